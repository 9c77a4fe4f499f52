"""The README documents the command line, the library and the Python module as they are: every
command, and every option of each, as the CLI's own --help lists them, every public header, and
every public name of the module and of its classes (one added without its documentation fails
here)."""

import functools
import pathlib
import re

import primseg
import pytest
from conftest import run_cli

ROOT = pathlib.Path(__file__).resolve().parents[2]
LONG_OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
COMMANDS = [
    "segment", "cut", "info", "eval", "batch", "denoise", "distance", "skeleton", "deform", "view"
]


@functools.cache
def readme():
    return (ROOT / "README.md").read_text(encoding="utf-8")


def section(first, following):
    """The README from its section `first` up to the section `following`."""
    text = readme()
    return text[text.index(f"\n## {first}\n") : text.index(f"\n## {following}\n")]


def command_line_part():
    """The synopses, then each command's own section (outputs, viewer, formats, batch, limits,
    denoising, skeletons)."""
    return section("Command line", "Library")


def synopses():
    """Each command's synopsis in the Command line block: its first line and the indented lines
    that continue it."""
    block = command_line_part().split("```")[1]
    result, command = {}, None
    for line in block.splitlines():
        match = re.match(r"primseg (\w+)", line)
        if match:
            command = match.group(1)
            result[command] = line
        elif command and line.startswith(" "):
            result[command] += "\n" + line
    return result


def commands(cli):
    listing = run_cli(cli, "--help").split("Subcommands:", 1)[1]
    return re.findall(r"^  (\w+) ", listing, flags=re.MULTILINE)


def test_every_command_has_a_synopsis(cli):
    listed = commands(cli)
    assert sorted(synopses()) == sorted(listed)
    assert sorted(COMMANDS) == sorted(listed), "a new command: add it to COMMANDS below"


@pytest.mark.parametrize("command", COMMANDS)
def test_every_option_of_a_command_is_documented_and_every_documented_one_exists(cli, command):
    help_text = run_cli(cli, command, "--help")
    options = set(LONG_OPTION.findall(help_text.split("Options:", 1)[1])) - {"--help"}
    assert options, help_text
    documented = set(LONG_OPTION.findall(command_line_part()))
    # An option with a short form (-o,--output) may be documented by it alone, as the synopses do.
    pairs = re.findall(r"(-\w),(--[a-z][a-z0-9-]*)", help_text)
    short_forms = {long: short for short, long in pairs}
    synopsis = synopses()[command]
    undocumented = sorted(
        option
        for option in options - documented
        if not re.search(rf"(?<![\w-]){short_forms.get(option, option)}\b", synopsis)
    )
    assert not undocumented, f"primseg {command}: not in the README: {undocumented}"
    unknown = sorted(set(LONG_OPTION.findall(synopsis)) - options)
    assert not unknown, f"primseg {command}: the README's synopsis names {unknown}"


def test_every_public_name_of_the_module_and_its_classes_is_documented():
    python_part = section("Python", "How it works")
    undocumented = []
    for name in dir(primseg):
        if name.startswith("_"):
            continue
        members = [name]
        value = getattr(primseg, name)
        if isinstance(value, type) and not issubclass(value, BaseException):  # not args, errno...
            members += [f"{name}.{m}" for m in dir(value) if not m.startswith("_")]
        for member in members:
            if not re.search(rf"\b{re.escape(member.split('.')[-1])}\b", python_part):
                undocumented.append(member)
    assert not undocumented, f"not in the README's Python section: {undocumented}"


def test_every_public_header_is_in_the_readme():
    include = ROOT / "include" / "primseg"
    missing = sorted(
        str(header.relative_to(include))
        for header in include.rglob("*.hpp")
        if header.name not in readme() and f"{header.parent.name}/*.hpp" not in readme()
    )
    assert not missing, f"public headers the README does not name: {missing}"
