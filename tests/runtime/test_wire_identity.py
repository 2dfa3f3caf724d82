"""A wire's digest: the SHA-256 of its canonical values, independent of how a file writes them."""
import hashlib
import math
import tomllib

from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.parameters import PARAMETER_SPECS
from sma_fmu.runtime.wire_identity import canonical_text, is_digest, wire_digest
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file

SPECS = {spec.name: spec for spec in PARAMETER_SPECS}


def _by_the_documented_rule(path):
    """The digest computed from the TOML file by the rule of docs/fmus.md, without sma-fmu's
    reader: header line, then name=repr(float(value)) sorted by name, memory_depth and
    stress_max with their defaults when the file omits them."""
    with open(path, "rb") as stream:
        document = tomllib.load(stream)
    values = {key: float(entry["value"]) for section, entries in document.items()
              if section != "wire" for key, entry in entries.items()}
    values.setdefault("memory_depth", 64.0)
    values.setdefault("stress_max", 300.0)
    text = "sma-fmu wire 1\n" + "".join(f"{name}={values[name]!r}\n" for name in sorted(values))
    return "sha256:" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def test_the_digest_follows_the_documented_rule(parameter_set):
    digest = parameter_set.digest
    assert is_digest(digest) and digest == wire_digest(parameter_set.params)
    assert digest == _by_the_documented_rule(default_parameter_file())
    lines = canonical_text(parameter_set.params).splitlines()
    assert lines[0] == "sma-fmu wire 1" and lines[1:] == sorted(lines[1:])
    assert "memory_depth=64.0" in lines and not any(line.startswith("alpha=") for line in lines)


def test_formatting_comments_meanings_and_order_do_not_count(tmp_path, parameter_set):
    text = default_parameter_file().read_text(encoding="utf-8")
    other = (text.replace("value = 0.15e-3,", "value = 1.5e-4,")
             .replace("value = 33.0,", "value = 33,")
             .replace('meaning = "wire resistance if all P phase"', 'meaning = "another meaning"')
             .replace('name = "reference"', 'name = "renamed"'))
    other = "# a comment of its own\n" + other
    # the [thermal] table moved to the top: another order of entries
    start = other.index("[thermal]")
    end = other.index("[sensing]")
    other = other[:start] + other[end:] + "\n" + other[start:end]
    assert other != text
    path = tmp_path / "reformatted.toml"
    path.write_text(other, encoding="utf-8")
    again = load_parameter_set(path)
    assert again.name == "renamed" and again.digest == parameter_set.digest
    assert again.digest == _by_the_documented_rule(path)


def test_one_ulp_or_a_given_default_changes_it(tmp_path, parameter_set):
    params = parameter_set.params
    nudged = params.replace(R_P=math.nextafter(params.R_P, math.inf))
    assert nudged.R_P != params.R_P and wire_digest(nudged) != parameter_set.digest
    # written and read back, the nudged value keeps its digest (repr round-trips)
    path = write_parameter_file(tmp_path / "nudged.toml", nudged, "nudged")
    assert load_parameter_set(path).digest == wire_digest(nudged)
    # an optional term given at the value the model takes in its place: the file says more
    given = params.replace(w2=0.0)
    assert given.terms == params.terms and wire_digest(given) != parameter_set.digest


def test_a_written_fit_round_trips_its_digest(tmp_path, parameter_set):
    two_stage = parameter_set.params.replace(w2=0.3, a2_h=120.0, a2_c=95.0, alpha_P=-4e-5,
                                             span_ratio_0=0.7, span_stress=120.0)
    path = write_parameter_file(tmp_path / "fit.toml", two_stage, "fit", "",
                                parameter_set.meanings)
    loaded = load_parameter_set(path)
    assert loaded.digest == wire_digest(two_stage) == _by_the_documented_rule(path)
    assert loaded.record() == {"file": str(path), "digest": loaded.digest}
    assert loaded.as_json()["wire_digest"] == loaded.digest


def test_sma_fmu_wire_prints_the_digest(tmp_path, capsys, parameter_set):
    import json

    from sma_fmu.cli import main

    nudged = parameter_set.params.replace(a_h=math.nextafter(68.0, 0.0))
    path = write_parameter_file(tmp_path / "nudged.toml", nudged, "nudged")
    assert main(["wire", "--model", str(path), "--json"]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["digest"] == wire_digest(nudged) != parameter_set.digest
