"""The command line's help: every option states its default once, and the scenarios are
listed by ``sma-fmu examples``."""
import argparse
import re

from sma_fmu.cli import build_parser, main
from sma_fmu.cli.arguments import HelpFormatter
from sma_fmu.cosim.scenario import scenario_names


def _parsers(parser, path=("sma-fmu",)):
    yield " ".join(path), parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                yield from _parsers(child, path + (name,))


def test_no_help_text_states_a_default_twice():
    formatter = HelpFormatter("sma-fmu")
    seen, doubled = 0, []
    for where, parser in _parsers(build_parser()):
        for action in parser._actions:
            if action.help in (None, argparse.SUPPRESS):
                continue
            text = formatter._get_help_string(action)
            seen += "default" in text
            appended = text != action.help   # the formatter added "(default: ...)"
            notes = re.findall(r"\(default[^)]*\)", text % {"default": action.default})
            if (appended and "(default" in action.help) or len(notes) != len(set(notes)):
                doubled.append(f"{where} {'/'.join(action.option_strings)}: {text}")
    assert seen > 30 and doubled == []


def test_build_help_says_its_fmi_default_once(capsys):
    try:
        main(["build", "--help"])
    except SystemExit:
        pass
    text = " ".join(capsys.readouterr().out.split())
    assert text.count("(default: 2)") == 1 and "(default: 2) (default: 2)" not in text


def test_examples_lists_every_shipped_scenario(capsys):
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("scenarios (sma-fmu run NAME")
    for name in scenario_names():
        assert f"  {name} " in out
    assert "constant_load.csv" in out


def test_examples_copies_the_scenarios_too(tmp_path, capsys):
    assert main(["examples", "--out", str(tmp_path / "ex")]) == 0
    copied = sorted(p.stem for p in (tmp_path / "ex" / "scenarios").glob("*.toml"))
    assert copied == sorted(scenario_names()) and len(copied) >= 18
    assert main(["run", str(tmp_path / "ex" / "scenarios" / "heavy-pi.toml"), "--path", "library",
                 "--out", str(tmp_path / "r")]) == 0
    # a scenario on another wire names it as ../models/NAME.toml: the copy loads
    from sma_fmu.cosim.scenario import load_scenario
    stroke = load_scenario(tmp_path / "ex" / "scenarios" / "flexinol-stroke-profile-pi+ff-adaptive.toml")
    assert stroke.parameter_set.params.terms.two_stage
