"""The C control blocks (c_family/runtime: pi_control, pwm, signals, scenario_signals and the
JSON reader of their String parameters) equal the Python runtime's, step by step and bit for
bit, on long random walks.

PI: gains from 0 up, inputs that clamp the power at 0 W and integrate or hold. PWM: switching
frequencies from 1e-6 Hz to 1 GHz, demands crossing 0 and peak_W, steps on and off the period
grid, times that a host adds up (Ecos), takes as k h (OMSimulator) or jitters, and times so
large that the period index leaves int64 (Python's ints; the C keeps them exact). Signals:
every reference kind and load tables, stepped on and off the time grid as hosts pass it.
Every output of every step must be equal (no tolerance: the same operations in the same
order on the same machine). The saved state round-trips through C mid-walk. Bad inputs,
bad states and malformed JSON texts are refused by both with the same message (numbers
compared as numbers where C prints %.17g and Python repr). The files compile clean with
mingw-w64 under -Werror.
"""
import json
import math
import random
import re
import struct

import pytest

from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.runtime.scenario_signals import SignalSource, grid_point, signals_from_text

from c_control import (MODULES, CPIController, CPwmDriver, CSignalSource, c_json, c_number,
                       load_library, normalized)
from c_runtime import compile_win64


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_library(tmp_path_factory.mktemp("c_control"))


def refused(call):
    """The refusal's message, or None when the call went through."""
    try:
        call()
    except (ValueError, OverflowError) as error:
        return str(error)
    return None


_TRAILING_COMMA = re.compile(r"Illegal trailing comma before end of (object|array): "
                             r"line \d+ column \d+ \(char (\d+)\)")


def json_message(message, *texts):
    """Python's json message as 3.11 and 3.12 word it, which the C reader follows: from 3.13 a
    trailing comma (in one of ``texts``) is 'Illegal trailing comma before end of object'
    at the comma, before it was 'Expecting property name enclosed in double quotes'
    (object) or 'Expecting value' (array) at the closing bracket (issue 32)."""
    def older(match):
        comma = int(match.group(2))
        text = next(t for t in texts if t[comma:comma + 1] == ",")
        rest = text[comma + 1:]
        end = comma + 1 + len(rest) - len(rest.lstrip(" \t\n\r"))
        return str(json.JSONDecodeError("Expecting property name enclosed in double quotes"
                                        if match.group(1) == "object" else "Expecting value", text, end))
    return message if message is None else _TRAILING_COMMA.sub(older, message)


def same_refusal(python_message, c_message):
    assert python_message is not None and c_message is not None, (python_message, c_message)
    assert normalized(c_message).startswith(normalized(python_message)), (python_message,
                                                                          c_message)


def host_times(rng, start, h, steps):
    """(t, step_size) pairs as hosts pass them: added up, k h, jittered or variable."""
    style = rng.choice(("added", "grid", "jitter", "variable"))
    t = start
    for k in range(steps):
        if style == "grid":
            t, size = start + k * h, (start + (k + 1) * h) - (start + k * h)
        elif style == "variable":
            size = h * rng.choice((1.0, 0.5, 2.0, 1.0 + 1e-7, 1.0 - 1e-13, rng.uniform(0.1, 3)))
        else:
            size = h
        yield (t + rng.uniform(-1e-9, 1e-9) * h if style == "jitter" else t), size
        if style != "grid":
            t = t + size


@pytest.mark.parametrize("seed", range(6))
def test_pi_controller_equals_python(lib, seed):
    rng = random.Random(seed)
    Kp, Ki = rng.choice((0.0, rng.uniform(0, 5))), rng.choice((0.0, rng.uniform(0, 50)))
    python, c = PIController(Kp, Ki), CPIController(lib, Kp, Ki)
    for k in range(20000):
        R, R_ref = rng.uniform(30, 50), rng.uniform(30, 50)
        P_ff, h = rng.uniform(-3, 3), rng.choice((1e-3, rng.uniform(1e-5, 1e-1)))
        assert c.preview(R, R_ref, P_ff) == python.preview(R, R_ref, P_ff)
        assert c.sample(R, R_ref, P_ff, h) == python.sample(R, R_ref, P_ff, h), k
        assert c.state() == [python.integral]
        if k % 997 == 0:   # through the saved state into a fresh controller
            fresh = CPIController(lib, Kp, Ki)
            fresh.restore(c.state())
            c = fresh


def test_pi_controller_refusals(lib):
    for Kp, Ki in ((-1.0, 1.0), (1.0, -0.5), (math.nan, 1.0), (1.0, math.inf)):
        same_refusal(refused(lambda: PIController(Kp, Ki)),
                     refused(lambda: CPIController(lib, Kp, Ki)))
    python, c = PIController(2.0, 10.0), CPIController(lib, 2.0, 10.0)
    python.sample(40.0, 41.0, 0.5, 1e-3), c.sample(40.0, 41.0, 0.5, 1e-3)
    for args in ((math.nan, 40, 0, 1e-3), (40, math.inf, 0, 1e-3), (40, 40, -math.inf, 1e-3),
                 (40, 40, 0, 0.0), (40, 40, 0, -1e-3), (40, 40, 0, math.nan)):
        same_refusal(refused(lambda: python.sample(*args)), refused(lambda: c.sample(*args)))
        assert c.state() == [python.integral]
    for bad in (math.nan, math.inf, -math.inf):
        same_refusal(refused(lambda: python.restore({"integral": bad})),
                     refused(lambda: c.restore([bad])))
    assert "PI state" in refused(lambda: c.restore([]))
    assert "PI state" in refused(lambda: c.restore([1.0, 2.0]))
    assert c.state() == [python.integral]


PWM_FREQUENCIES = (1e-6, 3.7e-3, 0.5, 50.0, 1000.0, 2.2e4, 1e6, 3.3e7, 1e9)


@pytest.mark.parametrize("frequency", PWM_FREQUENCIES)
def test_pwm_driver_equals_python(lib, frequency):
    rng = random.Random(int(frequency * 1e6) % 2**32)
    for walk in range(12):
        peak = rng.uniform(0.5, 20.0)
        python, c = PwmDriver(frequency, peak), CPwmDriver(lib, frequency, peak)
        h = 10 ** rng.uniform(-7, 0.5) if walk % 3 else rng.choice((1e-3, 1 / frequency))
        start = rng.choice((0.0, -1e-300, rng.uniform(-10, 10), 10 ** rng.uniform(3, 8)))
        for k, (t, size) in enumerate(host_times(rng, start, h, 1500)):
            demand = rng.choice((rng.uniform(-0.3, 1.3), rng.uniform(0, 1))) * peak
            assert c.step(demand, t, size) == python.step(demand, t, size), (walk, k)
            assert c.held() == python.held
            assert math.copysign(1.0, c.state()[0]) > 0 or c.state()[0] != 0   # no index -0
            if k % 499 == 0:
                fresh = CPwmDriver(lib, frequency, peak)
                fresh.restore(c.state())
                c = fresh


def test_pwm_driver_beyond_int64(lib):
    """Period indices past 2^53 and 2^63: Python's ints, the C's exact (base, minus one)."""
    rng = random.Random(7)
    for frequency in (1e9, 50.0, 1e-6):
        python, c = PwmDriver(frequency, 10.0), CPwmDriver(lib, frequency, 10.0)
        for k in range(4000):
            t = rng.choice((10 ** rng.uniform(6, 308), -(10 ** rng.uniform(6, 308)),
                            2.0 ** 63 / frequency, 2.0 ** 53 / frequency,
                            -(2.0 ** 53 + rng.choice((0, 2, 4, 64))) / frequency))
            size = rng.choice((1e-3, abs(t) * rng.uniform(1e-17, 1e-14), abs(t) * 2.0 ** -52,
                               abs(t) * rng.uniform(0.1, 3)))
            demand = rng.uniform(-2, 12)
            outcome = []
            expected = refused(lambda: outcome.append(python.step(demand, t, size)))
            got = refused(lambda: outcome.append(c.step(demand, t, size)))
            if expected is None:
                assert got is None and outcome[0] == outcome[1], (k, t, size, outcome)
            else:   # OverflowError: the period index t f is infinite; nothing changed
                same_refusal(expected, got)
            assert c.held() == python.held and c.state()[3] == python.power, k


def test_pwm_driver_refusals(lib):
    for frequency, peak in ((0.0, 1.0), (-5.0, 1.0), (math.nan, 1.0), (9e-7, 1.0), (1.1e9, 1.0),
                            (math.inf, 1.0), (50.0, 0.0), (50.0, -1.0), (50.0, math.nan)):
        same_refusal(refused(lambda: PwmDriver(frequency, peak)),
                     refused(lambda: CPwmDriver(lib, frequency, peak)))
    python, c = PwmDriver(50.0, 8.0), CPwmDriver(lib, 50.0, 8.0)
    python.step(3.0, 0.0, 1e-3), c.step(3.0, 0.0, 1e-3)
    for args in ((math.nan, 0.0, 1e-3), (1.0, math.inf, 1e-3), (1.0, 0.0, 0.0),
                 (1.0, 0.0, -1.0), (1.0, -math.inf, 1e-3)):
        same_refusal(refused(lambda: python.step(*args)), refused(lambda: c.step(*args)))
        assert c.held() == python.held and c.state()[3] == python.power
    bad_states = [  # (Python's state, the C's doubles)
        ({"held": [1.5, 0.5], "power": 1.0}, [1.5, 0.0, 0.5, 1.0]),
        ({"held": [3, math.nan], "power": 1.0}, [3.0, 0.0, math.nan, 1.0]),
        ({"held": [3, 1.5], "power": 1.0}, [3.0, 0.0, 1.5, 1.0]),
        ({"held": [3, -0.1], "power": 1.0}, [3.0, 0.0, -0.1, 1.0]),
        ({"held": None, "power": math.inf}, [math.nan, 0.0, math.nan, math.inf]),
        ({"held": None, "power": 9.0}, [math.nan, 0.0, math.nan, 9.0]),
        ({"held": None, "power": -1.0}, [math.nan, 0.0, math.nan, -1.0]),
    ]
    for python_state, c_state in bad_states:
        expected = refused(lambda: python.restore(python_state))
        got = refused(lambda: c.restore(c_state))
        assert got is not None and expected is not None
        assert normalized(got).split(" got")[0] == normalized(expected).split(" got")[0]
        assert c.held() == python.held
    assert "held" in refused(lambda: c.restore([3.0, 0.5, 0.5, 1.0]))   # minus_one 0 or 1
    assert "PWM state" in refused(lambda: c.restore([1.0, 0.0, 0.5]))


def reference_tables(rng):
    """One random table of every reference kind (a scenario file's [reference])."""
    times = sorted(rng.sample(range(1, 400), 6))
    yield {"kind": "constant", "value_ohm": rng.uniform(30, 50)}
    yield {"kind": "step", "initial_ohm": 44.0, "final_ohm": 38.5, "time_s": rng.uniform(0, 3)}
    yield {"kind": "ramp", "start_ohm": 45, "end_ohm": 37.25, "start_time_s": 0.5,
           "end_time_s": rng.uniform(1, 4)}
    for kind in ("sine", "cosine"):
        yield {"kind": kind, "offset_ohm": 41.85, "amplitude_ohm": rng.uniform(-6, 6),
               "frequency_hz": rng.uniform(0, 5), "phase_deg": rng.uniform(-180, 180)}
    yield {"kind": "table", "times_s": [t / 100 for t in times],
           "values_ohm": [rng.uniform(35, 48) for _ in times]}


@pytest.mark.parametrize("seed", range(4))
def test_signal_source_equals_python(lib, seed):
    rng = random.Random(seed)
    load = {"times_s": [0.0, 0.25, 1.0, 1.75, 2.5], "values_kg": [0.0032, 0.05, 0.15, 0, 0.1]}
    for table in reference_tables(rng):
        texts = json.dumps(table, separators=(",", ":")), json.dumps(load)
        for start in (0.0, rng.uniform(-1, 1)):
            h = rng.choice((1e-3, 0.1, rng.uniform(1e-4, 0.05)))
            python = SignalSource(*signals_from_text(*texts), start)
            c = CSignalSource(lib, *texts, start)
            for k, (t, size) in enumerate(host_times(rng, start, h, 2000)):
                assert c.step(t, size) == tuple(python.step(t, size)), (table, k)
                assert c.state() == [python.time]
                if k % 701 == 700 and python.time >= 0.0:   # restore into fresh sources
                    saved = python.state()
                    python = SignalSource(*signals_from_text(*texts), start)
                    python.restore(saved)
                    c.free()
                    c = CSignalSource(lib, *texts, start)
                    c.restore([saved["time"]])
            c.free()


def test_signal_source_refusals(lib):
    """Bad steps, bad saved times and math.sin's domain error: refused alike, nothing changed
    (but the first step's size, which Python takes before it checks the end)."""
    texts = ('{"kind":"sine","offset_ohm":40,"amplitude_ohm":2,"frequency_hz":1e300}',
             '{"times_s":[0],"values_kg":[0.05]}')
    python = SignalSource(*signals_from_text(*texts), 0.0)
    c = CSignalSource(lib, *texts, 0.0)
    for t, size in ((math.nan, 1e-3), (0.0, 0.0), (0.0, -1.0), (1e10, 1e-3), (0.0, math.inf),
                    (1.7e308, 1.7e308)):
        same_refusal(refused(lambda: python.step(t, size)), refused(lambda: c.step(t, size)))
        assert c.state() == [python.time]
    # the first step's size (1e-3, from the domain error's step) now puts 2e-3 on the grid
    assert c.step(1e-3 + 1e-12, 1e-3) == tuple(python.step(1e-3 + 1e-12, 1e-3))
    assert c.state() == [python.time] == [0.002]
    for bad in (-1.0, math.nan, math.inf, 1e10):   # 1e10 s: math.sin's domain error
        same_refusal(refused(lambda: python.restore({"time": bad})),
                     refused(lambda: c.restore([bad])))
        assert c.state() == [python.time]
    assert "signals state" in refused(lambda: c.restore([]))
    same_refusal(refused(lambda: SignalSource(*signals_from_text(*texts), math.inf)),
                 refused(lambda: CSignalSource(lib, *texts, math.inf)))
    c.free()


def test_grid_point_equals_python(lib):
    rng = random.Random(3)
    import ctypes
    for _ in range(50000):
        step = 10 ** rng.uniform(-6, 1)
        start = rng.choice((0.0, -0.0, rng.uniform(-5, 5)))
        t = start + rng.randint(0, 10 ** 6) * step * (1 + rng.choice((0, 1e-16, 1e-7, 2e-6)))
        t = rng.choice((t, t + rng.uniform(-2e-6, 2e-6) * step, 1e300, -t))
        grid = ctypes.c_double()
        found = lib.grid_point(ctypes.c_double(t), ctypes.c_double(start), ctypes.c_double(step),
                               ctypes.byref(grid))
        assert repr(grid.value if found else None) == repr(grid_point(t, start, step))  # -0.0


BAD_TEXTS = [  # (reference, load_profile): each refused by Python, C must refuse alike
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0],"values_kg":[0.1]}'),  # (accepted)
    ("", '{"times_s":[0],"values_kg":[0]}'), ("{", "{}"), ('{"kind":"constant"}', "{}"),
    ('{"kind":"constant","value_ohm":NaN}', "{}"), ('{"kind":"constant","value_ohm":1e400}', "{}"),
    ('{"kind":"constant","value_ohm":"40"}', "{}"), ('{"kind":"constant","value_ohm":true}', "{}"),
    ('{"kind":"constant","value_ohm":-Infinity}', "{}"), ('{"kind":"bogus"}', "{}"),
    ('{"value_ohm":40}', "{}"), ('{"kind":7}', "{}"), ('[1, 2]', "{}"), ('"text"', "{}"),
    ('{"kind":"constant","value_ohm":0}', "{}"), ('{"kind":"constant","value_ohm":2e6}', "{}"),
    ('{"kind":"step","initial_ohm":40,"final_ohm":38,"time_s":1,"zeta":1,"alpha":2}', "{}"),
    ('{"kind":"ramp","start_ohm":1,"end_ohm":2,"start_time_s":3,"end_time_s":3}', "{}"),
    ('{"kind":"sine","offset_ohm":40,"amplitude_ohm":50,"frequency_hz":1}', "{}"),
    ('{"kind":"cosine","offset_ohm":40,"amplitude_ohm":5,"frequency_hz":-1}', "{}"),
    ('{"kind":"table","times_s":[0,1,1],"values_ohm":[40,41,42]}', "{}"),
    ('{"kind":"table","times_s":[0,1],"values_ohm":[40]}', "{}"),
    ('{"kind":"table","times_s":[],"values_ohm":[]}', "{}"),
    ('{"kind":"table","times_s":5,"values_ohm":[1]}', "{}"),
    ('{"kind":"table","times_s":[0,"a"],"values_ohm":[1,2]}', "{}"),
    ('{"kind":"constant","value_ohm":40,"kind":"step"}', "{}"),
    ('{"kind":"constant","value_ohm":40}', ""),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0,1]}'),
    ('{"kind":"constant","value_ohm":40}', '{"values_kg":[0]}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[1],"values_kg":[0]}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0,2,1],"values_kg":[0,1,2]}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0,1],"values_kg":[0,-0.5]}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0,1],"values_kg":[0]}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0],"values_kg":[0],"extra":1}'),
    ('{"kind":"constant","value_ohm":40}', '{"times_s":[0],"values_kg":[null]}'),
    ('{"kind":"constant","value_ohm":40}', "[]"), ('{"kind":"constant","value_ohm":40} x', "{}"),
    ('{"kind":"constant",\n"value_ohm":40,}', "{}"), ('\ufeff{}', "{}"), ('{"a":"\x01"}', "{}"),
]


@pytest.mark.parametrize("texts", BAD_TEXTS)
def test_signal_texts_refused_alike(lib, texts):
    expected = json_message(refused(lambda: signals_from_text(*texts)), *texts)
    try:
        source = CSignalSource(lib, *texts)
    except ValueError as error:
        got = str(error)
    else:
        source.free()
        got = None
    assert got == expected


def mutations(rng, count):
    seeds = ['{"kind":"cosine","offset_ohm":41.85,"amplitude_ohm":6.05,"frequency_hz":0.5}',
             '{"times_s":[0.0,10.0,20.0],"values_kg":[0.0032,0.05,0.15]}',
             '{"kind": "table", "times_s": [0, 1e1, 2.5E-3], "values_ohm": [1, -0, 12345678901234567890]}',
             '[true, false, null, "a\\"b\\\\c\\u00e9\\ud83d\\ude00\\n", NaN, -Infinity]']
    pieces = list('{}[]":,. -+0123456789eEaNIfnrtul\\/\n\t\'') + ["\\u", "é", "\x01", "NaN"]
    for _ in range(count):
        text = rng.choice(seeds)
        for _ in range(rng.randint(0, 4)):
            i = rng.randint(0, len(text))
            text = text[:i] + rng.choice(pieces) + text[i + rng.randint(0, 2):]
        yield text


_ESCAPE = re.compile(r"\\\\|\\x[0-9a-f]{2}|\\u[0-9a-f]{4}|\\U[0-9a-f]{8}")


def unescaped(text):
    """A repr with its \\x, \\u, \\U escapes as the characters: the C knows Python's
    str.isprintable() only for the common non-printable code points (no Unicode database)."""
    return _ESCAPE.sub(lambda m: m.group() if m.group() == "\\\\" else chr(int(m.group()[2:], 16)),
                       text)


def test_json_reader_equals_python(lib):
    """Mutated texts: accepted alike (the same value, by repr), refused alike (the same
    decoder message and position)."""
    rng, accepted = random.Random(11), 0
    for text in mutations(rng, 20000):
        try:
            expected = "OK", repr(json.loads(text))
            accepted += 1
        except ValueError as error:
            expected = "ERR", json_message(str(error), text)
        got = c_json(lib, text)
        assert got == expected or (got[0] == expected[0] == "OK"
                                   and unescaped(got[1]) == unescaped(expected[1])), text
    assert accepted > 2000
    assert c_json(lib, "[" * 64 + "]" * 64)[0] == "OK"
    assert c_json(lib, "[" * 65 + "]" * 65) == (
        "ERR", "maximum recursion depth exceeded while decoding a JSON array from a unicode string")
    assert c_json(lib, " " * (8 << 20) + "1")[0] == "ERR"


def test_json_numbers_as_python(lib):
    """Decimal -> double as Python's float(): random doubles written shortest, with 17 and 25
    digits, and the exact midpoints between neighbouring doubles (ties to even)."""
    from decimal import Decimal, getcontext
    getcontext().prec = 1200
    rng = random.Random(5)
    for _ in range(20000):
        x = struct.unpack("<d", struct.pack("<Q", rng.getrandbits(63)))[0]
        if not math.isfinite(x):
            continue
        for text in (repr(x), "%.17e" % x, "%.25e" % x):
            assert c_number(lib, text) == float(text), text
        following = math.nextafter(x, math.inf)
        if math.isfinite(following):
            middle = (Decimal(x) + Decimal(following)) / 2
            for text in (format(middle, "e"), format(middle.next_plus(), "e"),
                         format(middle.next_minus(), "e")):
                assert c_number(lib, text) == float(text), text
    for text in ("1e400", "1e-400", "2.4703282292062328e-324", "1.7976931348623158e308",
                 "0." + "0" * 1000 + "1", "9007199254740993", "1" * 300 + "e-300"):
        assert c_number(lib, text) == float(text), text


def test_runtime_compiles_clean_for_win64(tmp_path):
    objects = compile_win64(MODULES, tmp_path)
    assert objects is not None, "x86_64-w64-mingw32-gcc is not installed"
    assert all(path.stat().st_size > 0 for path in objects)
