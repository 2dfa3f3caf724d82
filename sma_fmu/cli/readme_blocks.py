"""The README's generated blocks: text written from the code, so it cannot go stale.

A block lies between ``<!-- generated:NAME -->`` and ``<!-- /generated:NAME -->`` (the
markers of docs/fmus.md's variable tables); :data:`BLOCKS` names its generator. ``cli``:
every command of the argparse tree (:func:`sma_fmu.cli.build_parser`) with its arguments
and its help. ``performance`` (README) and ``benchmark`` (docs/performance.md): the
tables of one recorded ``sma-fmu bench`` run, docs/benchmark.json, with its date and the
machine's baseline. ``python -m sma_fmu.cli.readme_blocks [--record FILE]`` rewrites the
blocks; tests/project/test_readme.py fails when one differs from what its generator writes now.
"""
import argparse
import re
import sys
import textwrap
from pathlib import Path

__all__ = ["WIDTH", "BLOCKS", "command_entries", "command_list", "markers", "render_blocks", "main"]

WIDTH = 96   # characters of a line in the block, before the README's 4-space code indent


def _choices(action):
    return "|".join(str(choice) for choice in action.choices)


def _metavar(action):
    if action.metavar is not None:
        return action.metavar
    if action.choices is not None:
        return _choices(action)
    return action.dest.upper() if action.option_strings else action.dest


def _unit(action):
    """One argument as usage shows it: ``NAME``, ``NAME...``, ``[NAME...]``, ``[--out DIR]``."""
    if not action.option_strings:
        name = _metavar(action)
        return {None: name, "+": f"{name}...", "*": f"[{name}...]", "?": f"[{name}]"}[action.nargs]
    flag = next((s for s in action.option_strings if s.startswith("--")), action.option_strings[0])
    text = flag if action.nargs == 0 else f"{flag} {_metavar(action)}"
    return text if action.required else f"[{text}]"


def _subcommands(parser):
    """[(name, help, subparser)] of the parser's sub-commands, in the order they were added."""
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            found += [(name, helps.get(name, ""), sub) for name, sub in action.choices.items()]
    return found


def command_entries(parser, words=("sma-fmu",), help_text=""):
    """[(command words, usage units, help)] of every leaf command under ``parser``: its own
    options first when it has sub-commands (``sma-fmu --version``), then each sub-command's."""
    subcommands = _subcommands(parser)
    actions = [action for action in parser._actions
               if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))]
    positionals = [_unit(a) for a in actions if not a.option_strings]
    options = [_unit(a) for a in actions if a.option_strings]
    if not subcommands:
        return [(list(words), positionals + options, help_text)]
    entries = [(list(words), [unit.strip("[]")], action.help or "")
               for unit, action in zip(options, (a for a in actions if a.option_strings))]
    for name, text, sub in subcommands:
        entries += command_entries(sub, (*words, name), text)
    return entries


def _wrap_usage(words, units):
    lines, line = [], " ".join(words)
    for unit in units:
        if len(line) + 1 + len(unit) > WIDTH:
            lines.append(line)
            line = " " * 8 + unit
        else:
            line += " " + unit
    return lines + [line]


def command_list(parser=None):
    """The ``cli`` block: each command's usage, wrapped at :data:`WIDTH`, its help below it."""
    if parser is None:
        from sma_fmu.cli import build_parser
        parser = build_parser()
    lines = []
    for words, units, text in command_entries(parser):
        lines += _wrap_usage(words, units)
        lines += textwrap.wrap(" ".join(text.split()), WIDTH, initial_indent=" " * 4,
                               subsequent_indent=" " * 4, break_on_hyphens=False,
                               break_long_words=False)
    return "\n".join(("    " + line).rstrip() for line in lines)


BENCHMARK_RECORD = Path("docs") / "benchmark.json"   # one `sma-fmu bench` run, with its date


def _record(root):
    import json
    return json.loads((Path(root) / BENCHMARK_RECORD).read_text(encoding="utf-8"))


def _heading(record):
    machine = record["machine"]
    return (f"`sma-fmu bench --runs {record['runs']}` on {record['recorded_on']}, one run on "
            f"the 2-core development VM: Python {machine['python']}, plain-Python baseline "
            f"{machine['python_loop_ns_per_iteration']} ns per iteration (compare ratios: the "
            f"VM's speed swings between hours). Regenerate: `sma-fmu bench --out DIR`, then "
            f"`python -m sma_fmu.cli.readme_blocks --record DIR/benchmark.json`.")


_SUMMARY_SECTIONS = ("Ratios", "Native (C) FMUs")      # whole sections, to their blank line
_SUMMARY_VERDICTS = ("SmaFeedforward step", "plain C host (front)", "slowest", "identification",
                     "mixed at", "gain grid at")


def performance_summary(root="."):
    """The ``performance`` block (README): the ratio sections and every target's verdict of
    the recorded bench run (:data:`BENCHMARK_RECORD`)."""
    from sma_fmu.bench.benchmark import format_table
    record = _record(root)
    keep, inside = [], False
    for line in format_table(record).splitlines():
        inside = (inside and bool(line.strip())) or line.startswith(_SUMMARY_SECTIONS)
        if inside or line.startswith(_SUMMARY_VERDICTS):
            keep.append(line)
    return "\n".join([_heading(record), "", "```", *keep, "```"])


def benchmark_table(root="."):
    """The ``benchmark`` block (docs/performance.md): the whole table of the recorded run."""
    from sma_fmu.bench.benchmark import format_table
    record = _record(root)
    return "\n".join([_heading(record), "", "```", format_table(record), "```"])


BLOCKS = {"cli": lambda root=".": command_list(), "performance": performance_summary,
          "benchmark": benchmark_table}


def markers(name):
    """The begin and end markers of block ``name``."""
    return f"<!-- generated:{name} -->", f"<!-- /generated:{name} -->"


def render_blocks(text, blocks=None, root="."):
    """``text`` with every block of ``blocks`` (name -> text; default: each generator of
    :data:`BLOCKS` that ``text`` marks, run now on the checkout at ``root``) replaced; text
    without markers is unchanged."""
    if blocks is None:
        blocks = {name: make(root) for name, make in BLOCKS.items() if markers(name)[0] in text}
    for name, content in blocks.items():
        begin, end = markers(name)
        block = (f"{begin}\n<!-- generated by `python -m sma_fmu.cli.readme_blocks`; do not edit -->"
                 f"\n\n{content}\n\n{end}")
        text = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _match: block, text,
                      flags=re.S)
    return text


DOCUMENTS = (Path("README.md"), Path("docs") / "performance.md")


def record_benchmark(source, root="."):
    """Copy a bench run's ``benchmark.json`` to :data:`BENCHMARK_RECORD`, with today's date."""
    import datetime
    import json
    record = json.loads(Path(source).read_text(encoding="utf-8"))
    if "fmu_step" not in record:
        raise ValueError(f"{source}: not a whole `sma-fmu bench` run (run it without --only)")
    record["recorded_on"] = datetime.date.today().isoformat()
    target = Path(root) / BENCHMARK_RECORD
    target.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    return target


def main(argv=None):
    """``python -m sma_fmu.cli.readme_blocks [--record FILE] [DOCUMENT...]``: rewrite the
    generated blocks of the README and docs/performance.md (run in the checkout)."""
    parser = argparse.ArgumentParser(prog="python -m sma_fmu.cli.readme_blocks",
                                     description="rewrite the generated blocks")
    parser.add_argument("documents", type=Path, nargs="*", default=list(DOCUMENTS))
    parser.add_argument("--record", type=Path, metavar="FILE",
                        help="first take this bench run's benchmark.json as docs/benchmark.json")
    args = parser.parse_args(argv)
    if args.record:
        try:
            print(f"recorded: {record_benchmark(args.record)}")
        except (OSError, ValueError) as error:
            parser.error(str(error))
    for document in args.documents:
        try:
            text = document.read_text(encoding="utf-8")
        except OSError as error:
            parser.error(f"{document}: {error.strerror}")
        found = [name for name in BLOCKS if markers(name)[0] in text]
        if not found:
            parser.error(f"{document}: no generated block ({' ... '.join(markers('NAME'))})")
        document.write_text(render_blocks(text), encoding="utf-8")
        print(f"{document}: generated block(s) {', '.join(found)} written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
