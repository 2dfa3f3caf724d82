"""The README cannot go stale: its generated blocks are what their generators write now, and
every ``sma-fmu`` command it shows exists in the argparse tree, with its options."""
import argparse
import re
from pathlib import Path

import pytest

from sma_fmu.cli import build_parser
from sma_fmu.cli.readme_blocks import BLOCKS, command_list, markers, render_blocks

README = Path(__file__).parents[2] / "README.md"
_OPTION = re.compile(r"^--?[A-Za-z][-\w]*")
_PLACEHOLDER = re.compile(r"^[A-Z_.0-9]|^\{|\.\.\.|<")   # FILE, SCENARIO..., <x>: not a literal


def shown_commands(text):
    """The ``sma-fmu ...`` commands the README shows: lines (and ``&&`` parts of lines) in
    fenced or indented code blocks and in the Command line section, and inline code spans."""
    found, fenced, section = [], False, ""
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
            continue
        if line.startswith("## "):
            section = line[3:].strip()
        code = fenced or line.startswith("    ") or section == "Command line"
        if code:
            for part in re.sub(r"\s#.*", "", line).split("&&"):
                if part.strip().startswith("sma-fmu "):
                    found.append(part.strip())
        if not fenced:
            found += re.findall(r"`(sma-fmu [^`]+)`", line)
    return found


def _subparsers(parser):
    return next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)


def _literal_choices(token, choices, what):
    """Problems of ``token`` (alternatives a|b) against ``choices``, unless a placeholder."""
    if choices is None or _PLACEHOLDER.search(token):
        return []
    return [f"{what}: {word!r} is not one of {', '.join(map(str, choices))}"
            for word in token.split("|") if word and word not in choices]


def command_problems(command, parser):
    """What in ``command`` (a line ``sma-fmu ...``) the argparse tree ``parser`` lacks: a
    sub-command, an option, or a literal value of a choice; [] when all exist."""
    tokens = command.split()[1:]
    words = ["sma-fmu"]
    while (sub := _subparsers(parser)) is not None and tokens and not tokens[0].startswith("-"):
        name = tokens.pop(0)
        if _PLACEHOLDER.search(name):   # sma-fmu COMMAND --help: any command
            return []
        if name not in sub.choices:
            return [f"{' '.join(words)}: no command {name!r}"]
        parser = sub.choices[name]
        words.append(name)
    if _subparsers(parser) is not None and not tokens:
        return [f"{' '.join(words)}: a sub-command is missing"]
    options = {flag: action for action in parser._actions for flag in action.option_strings}
    positionals = [action for action in parser._actions
                   if not action.option_strings and not isinstance(action, argparse._SubParsersAction)]
    problems, value_of = [], None
    for raw in tokens:
        token = raw.strip("[]")
        if not token or token == "/":
            continue
        if _OPTION.match(token):
            flag = token.split("=")[0]
            action = options.get(flag)
            if action is None:
                problems.append(f"{' '.join(words)}: no option {flag}")
            value_of = action if action is not None and action.nargs != 0 else None
        elif value_of is not None:
            problems += _literal_choices(token, value_of.choices, f"{' '.join(words)} {flag}")
            value_of = None
        elif positionals:
            action = positionals[0]
            problems += _literal_choices(token, action.choices, f"{' '.join(words)} {action.dest}")
            if action.nargs in (None, "?"):
                positionals.pop(0)
    return problems


@pytest.mark.parametrize("command, expected", [
    ("sma-fmu fit isobaric lab.csv --load 0.15 --lag fit", []),
    ("sma-fmu export cross-check --out DIR", []),
    ("sma-fmu launch paper", ["sma-fmu: no command 'launch'"]),
    ("sma-fmu export zip paper", ["sma-fmu export: no command 'zip'"]),
    ("sma-fmu run paper [--outt DIR]", ["sma-fmu run: no option --outt"]),
    ("sma-fmu fit isobaric|spherical FILE", ["sma-fmu fit experiment: 'spherical' is not one of "
                                             "constant-load, constant-temperature, isobaric"]),
    ("sma-fmu run paper --path fmu|cloud", ["sma-fmu run --path: 'cloud' is not one of "
                                            "fmu, library, ssp, container"]),
    ("sma-fmu export", ["sma-fmu export: a sub-command is missing"]),
    ("sma-fmu COMMAND --help", []),
])
def test_the_check_finds_what_the_tree_lacks(command, expected):
    assert command_problems(command, build_parser()) == expected


def test_every_command_the_readme_shows_exists():
    text = README.read_text(encoding="utf-8")
    commands = shown_commands(text)
    # the scan sees code blocks, the generated list and the fenced install line
    assert len(commands) > 30 and "sma-fmu export ssp paper --out ssp/" in commands
    assert "sma-fmu build [--out DIR] [--model FILE] [--native] [--fmi {2,3}] [--compile] [--quiet]" in commands
    assert commands.count("sma-fmu run paper") >= 2
    parser = build_parser()
    problems = {command: found for command in commands if (found := command_problems(command, parser))}
    assert problems == {}


@pytest.mark.parametrize("document, names", [("README.md", ("cli", "performance")),
                                             ("docs/performance.md", ("benchmark",))])
def test_the_generated_blocks_are_what_the_generators_write_now(document, names):
    root = README.parent
    text = (root / document).read_text(encoding="utf-8")
    for name in names:
        assert all(marker in text for marker in markers(name)), f"{document} lacks block {name}"
    assert render_blocks(text, root=root) == text, (
        f"{document}'s generated blocks are stale: run python -m sma_fmu.cli.readme_blocks")


def test_a_stale_block_is_seen():
    text = README.read_text(encoding="utf-8")
    begin = markers("performance")[0]
    inside = text.index(begin) + len(begin)
    stale = text[:inside] + "\n| old numbers | 24.7 us |\n" + text[inside:]
    assert render_blocks(stale, root=README.parent) == text


def _leaves(parser, words=("sma-fmu",)):
    """[(command words, parser)] of every command without sub-commands."""
    sub = _subparsers(parser)
    if sub is None:
        return [(" ".join(words), parser)]
    return [leaf for name, child in sub.choices.items() for leaf in _leaves(child, (*words, name))]


def test_the_command_list_shows_every_command_and_option_of_the_tree():
    """Each leaf command's entry (its usage lines up to its help) names all its options."""
    entries, current = {}, None
    for line in command_list().splitlines():
        if line.startswith("    sma-fmu "):
            current = line.strip()
            entries[current] = current
        elif line.startswith(" " * 12):
            entries[current] += " " + line.strip()
    leaves = _leaves(build_parser())
    assert len(leaves) >= 20
    for words, parser in leaves:
        entry = next((text for text in entries.values()
                      if text == words or text.startswith(words + " ")), None)
        assert entry is not None, words
        for action in parser._actions:
            flags = [flag for flag in action.option_strings if flag.startswith("--")]
            if flags and flags[0] != "--help":
                assert flags[0] in entry.split(" ") or f"[{flags[0]}" in entry or \
                    f"{flags[0]}]" in entry, (words, flags[0])
