"""User docs state facts, not internal items: README.md, docs/*.md, the package's shipped
texts (the FMUs' model pages, parameter files, scenarios, examples) and the CLI's help name
no issue number, and every relative link and every path into the repository they give names
something the repository has. The package's sources name no issue number either (a code
comment keeps the reason, not the ticket)."""
import argparse
import re
from pathlib import Path

import pytest

from sma_fmu.cli import build_parser

REPO = Path(__file__).resolve().parents[2]
PACKAGE = REPO / "sma_fmu"
ISSUE = re.compile(r"\bissues?[ -]#?\d+|\bissues? #\d+|\bDESIGN-\d+", re.IGNORECASE)
LINK = re.compile(r"\]\(([^)\s]+)\)")
EXTERNAL_LINK = re.compile(r"\[[^\]]*\]\([a-z]+:[^)]*\)")
TOP_DOC = re.compile(r"(?<![\w./-])([A-Z][A-Z0-9_-]+\.md)\b")   # README.md, CONTRIBUTING.md, ...
MACHINE_PATH = re.compile(r"(?<![\w.~])(/(?:work|root|home|scratch)/[^\s`'\")]*)")  # one machine's files
SHIPPED_TEXT = (".html", ".toml", ".md", ".py", ".txt", ".json")


def _ignored_folders():
    """The top-level folders .gitignore names (``results/``, ``fmus/``, ``build/``, ...): the
    commands' outputs, which the README's main job writes into the checkout."""
    lines = (REPO / ".gitignore").read_text(encoding="utf-8").splitlines()
    return {line.strip().rstrip("/") for line in lines if line.strip().endswith("/")
            and "/" not in line.strip().rstrip("/") and not line.startswith(("#", "!"))
            and "*" not in line}


def _repo_folders():
    ignored = _ignored_folders()
    return sorted(p.name for p in REPO.iterdir() if p.is_dir() and not p.name.startswith((".git", "__"))
                  and not p.name.endswith(".egg-info") and p.name not in ignored)


def _repo_path():
    """A path into one of the repository's folders (``sma_fmu/fmi/hosts/``, ``tests/x.py``)."""
    roots = "|".join(re.escape(name) for name in _repo_folders())
    return re.compile(rf"(?<![\w./~-])((?:{roots})/[\w./-]*)")


def _generated():
    """The paths .gitignore names: generated (the wheel's prebuilt binaries), never committed,
    but docs may say where they go."""
    lines = (REPO / ".gitignore").read_text(encoding="utf-8").splitlines()
    return {line.strip().rstrip("/") for line in lines
            if "/" in line.strip().rstrip("/") and not line.startswith("#") and "*" not in line}


def _help_texts(parser, name="sma-fmu"):
    yield name, parser.format_help()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for command, sub in action.choices.items():
                yield from _help_texts(sub, f"{name} {command}")


def user_docs():
    """{name: text} of the user docs: README, docs/, the shipped texts, the CLI's help."""
    files = [REPO / "README.md", REPO / "CONTRIBUTING.md", *sorted((REPO / "docs").glob("*.md"))]
    files += sorted(p for folder in ("models", "scenarios", "examples") for p in (PACKAGE / folder).rglob("*")
                    if p.suffix in SHIPPED_TEXT)
    files += sorted(PACKAGE.rglob("*.html"))   # the FMUs' model pages
    docs = {p.relative_to(REPO).as_posix(): p.read_text(encoding="utf-8") for p in files}
    docs.update(_help_texts(build_parser()))
    return docs


def test_the_doc_lists_are_not_empty():
    docs = user_docs()
    assert "README.md" in docs and "sma-fmu build" in docs
    assert sum(name.startswith("docs/") for name in docs) >= 5
    assert sum(name.endswith(".html") for name in docs) >= 5      # one page per model
    assert sum(name.endswith(".toml") for name in docs) >= 5


def test_user_docs_name_no_issue_number():
    found = [f"{name}: {match.group(0)!r} in {_line(text, match.start())!r}"
             for name, text in user_docs().items() for match in ISSUE.finditer(text)]
    assert found == []


def test_package_sources_name_no_issue_number():
    found = [f"{path.relative_to(REPO)}: {_line(text, match.start())!r}"
             for path in sorted(PACKAGE.rglob("*")) if path.suffix in (".py", ".c", ".h", ".toml")
             for text in [path.read_text(encoding="utf-8", errors="replace")]
             for match in ISSUE.finditer(text)]
    assert found == []


def _line(text, index):
    start = text.rfind("\n", 0, index) + 1
    end = text.find("\n", index)
    return text[start:end if end >= 0 else None].strip()


def _slug(heading):
    """GitHub's anchor of a Markdown heading."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip().lower()).replace("`", "")
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(path):
    anchors, counts, fenced = set(), {}, False
    for line in path.read_text(encoding="utf-8").splitlines():
        anchors.update(re.findall(r'<a (?:id|name)="([^"]+)"', line))   # an explicit anchor
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and (match := re.match(r"#{1,6} (.+)", line)):
            slug = _slug(match.group(1))
            anchors.add(slug if slug not in counts else f"{slug}-{counts[slug]}")
            counts[slug] = counts.get(slug, 0) + 1
    return anchors


def test_relative_links_resolve():
    broken = []
    for name, text in user_docs().items():
        if not name.endswith(".md"):
            continue
        for match in LINK.finditer(text):
            target = match.group(1)
            if re.match(r"[a-z]+:", target):
                continue   # https:, mailto:
            path, _, anchor = target.partition("#")
            resolved = (REPO / name).parent / path if path else REPO / name
            if not resolved.exists():
                broken.append(f"{name}: {target} (no {resolved})")
            elif anchor and resolved.suffix == ".md" and anchor not in _anchors(resolved):
                broken.append(f"{name}: {target} (no heading #{anchor} in {path or name})")
    assert broken == []


def test_repository_paths_exist():
    """Paths into the repository's folders and top-level docs exist; no path of one machine."""
    repo_path, generated = _repo_path(), _generated()
    missing = []
    for name, text in user_docs().items():
        for match in repo_path.finditer(text):
            path = match.group(1).rstrip(".,:;")
            if re.match(r"[<{*]", text[match.end():match.end() + 1]):
                continue   # a placeholder follows: sma_fmu/fmi/c_family/models/<Model>.c
            if not (REPO / path).exists() and path.rstrip("/") not in generated:
                missing.append(f"{name}: {path}")
        missing += [f"{name}: {path}" for path in MACHINE_PATH.findall(text)]
        local = EXTERNAL_LINK.sub("", text)   # [RULES.md](https://...): another repository's file
        missing += [f"{name}: {doc}" for doc in TOP_DOC.findall(local) if not (REPO / doc).is_file()]
    assert missing == []


@pytest.mark.parametrize("text, found", [
    ("the terms of issue 36 (`DESIGN-36.md`)", ["issue 36", "DESIGN-36"]),
    ("issues 38 and 39; Issue-12", ["issues 38", "Issue-12"]),
    ("an issue with 3 FMUs; a tissue 4", []),
])
def test_the_issue_pattern(text, found):
    assert [m.group(0) for m in ISSUE.finditer(text)] == found
