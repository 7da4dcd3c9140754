#!/usr/bin/env python3
"""The documentation names only commands, options and scene keys that the program has.

    tests/docs_consistency.py build/bin/rbdem .        # exit 0: consistent; 1: the mistakes, one per line

Checks, against the built binary:

1. every command line in a code block (indented or fenced) of README.md and docs/*.md that starts with `rbdem`
   (or `mpirun ... rbdem`): the subcommand is one that `rbdem --help` lists, every option it uses is one that
   `rbdem <command> --help` (or `rbdem --help` without a command) lists, every `--set section.key=value` names a
   key of `rbdem --help-scene`, and every `scenes/...` file it names exists in the repository;
2. every backquoted token of README.md and docs/*.md that looks like a scene key, `section.key` with section one
   of the scene's sections, is a key that `rbdem --help-scene` lists (`section.*` stands for the whole section).
   Skipped: docs/scene.md (it is the output of `rbdem --help-scene`) and docs/bad_inputs.md (it shows misspelt
   keys on purpose: the inputs rbdem refuses).

CTest: Docs.CommandsAndKeysExist.
"""
import glob
import os
import re
import subprocess
import sys

SECTIONS = ["specimen", "joint_set2", "joint_set", "mesh", "rock2", "rock", "beds", "joint2", "joint", "loading",
            "numerics", "elastic", "output"]
# `elastic.json`, `mesh.msh`, ...: file names, not keys.
FILE_EXTENSIONS = {"json", "md", "csv", "toml", "h5", "xdmf", "png", "msh", "py", "hpp", "cpp", "txt", "geo"}
SKIP_KEY_CHECK = {"scene.md", "bad_inputs.md"}


def run(rbdem, *args):
    p = subprocess.run([rbdem, *args], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        sys.exit(f"docs_consistency: `rbdem {' '.join(args)}` failed with status {p.returncode}:\n{p.stderr}")
    return p.stdout


def subcommands(help_text):
    """The names under 'Subcommands:' of CLI11's help."""
    names, inside = set(), False
    for line in help_text.splitlines():
        if line.startswith("Subcommands:"):
            inside = True
            continue
        if inside:
            m = re.match(r"^  (\S+)", line)
            if m:
                names.add(m.group(1))
            elif line and not line.startswith(" "):
                inside = False
    return names


def options(help_text):
    """Every -x and --long option a CLI11 help lists (the first column of its option lines)."""
    found = set()
    for line in help_text.splitlines():
        m = re.match(r"^  (-\S+)", line)
        if m:
            for name in m.group(1).split(","):
                found.add(name)
    return found


def scene_keys(help_scene):
    keys = set()
    for line in help_scene.splitlines()[1:]:
        if line.strip():
            keys.add(line.split()[0])
    return keys


def code_lines(text):
    """(line number, text) of the lines in fenced blocks and in indented blocks (4 spaces after a blank line)."""
    out, fenced, indented, previous_blank = [], False, False, True
    for n, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            out.append((n, line))
            continue
        if line.startswith("    ") and (indented or previous_blank):
            indented = True
            out.append((n, line))
        elif line.strip():
            indented = False
        previous_blank = not line.strip()
    return out


def command_words(line):
    """The words of an rbdem command line without its comment and launcher, or None for any other line."""
    words = line.split("#", 1)[0].split()
    if words[:1] == ["mpirun"] and "rbdem" in words:
        words = words[words.index("rbdem"):]
    if words[:1] != ["rbdem"]:
        return None
    return words[1:]


def check_commands(path, text, commands, opts_of, keys, source_dir, problems):
    for n, line in code_lines(text):
        words = command_words(line)
        if words is None:
            continue
        where = f"{path}:{n}: `{line.split('#', 1)[0].strip()}`"
        command = ""
        if words and not words[0].startswith("-"):
            if words[0].startswith("<"):  # a placeholder such as <command>
                continue
            command = words.pop(0)
            if command not in commands:
                problems.append(f"{where}: no command '{command}' (rbdem --help lists {', '.join(sorted(commands))})")
                continue
        known = opts_of[command]
        for k, word in enumerate(words):
            if word.startswith("-") and not re.match(r"^-\d", word):
                name = word.split("=", 1)[0]
                if name not in known:
                    shown = f"rbdem {command} --help" if command else "rbdem --help"
                    problems.append(f"{where}: `{shown}` lists no option '{name}'")
            if word == "--set" and k + 1 < len(words):
                key = words[k + 1].split("=", 1)[0]
                if key not in keys:
                    problems.append(f"{where}: --set {key}: no such scene key (rbdem --help-scene)")
            if word.startswith("scenes/") and not os.path.exists(os.path.join(source_dir, word)):
                problems.append(f"{where}: {word} is not in the repository")


KEY = re.compile(r"(?<![\w./-])(?:scene\.)?(%s)\.(\*|[A-Za-z_][A-Za-z0-9_]*)" % "|".join(SECTIONS))


def check_keys(path, text, keys, problems):
    # Inline code spans outside fenced blocks (a fence's backquotes would pair up with the prose's).
    fenced = False
    for n, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        for span in re.findall(r"`([^`]+)`", line):
            for m in KEY.finditer(span):
                section, name = m.group(1), m.group(2)
                if name in FILE_EXTENSIONS:
                    continue
                if name == "*":
                    if not any(k.startswith(section + ".") for k in keys):
                        problems.append(f"{path}:{n}: `{section}.*`: the scene has no section '{section}'")
                    continue
                key = f"{section}.{name}"
                if key not in keys:
                    problems.append(f"{path}:{n}: `{span}` names '{key}', which rbdem --help-scene does not list")


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: docs_consistency.py RBDEM SOURCE_DIR")
    rbdem, source_dir = sys.argv[1], sys.argv[2]
    top = run(rbdem, "--help")
    commands = subcommands(top)
    if not commands:
        sys.exit("docs_consistency: found no subcommands in `rbdem --help`")
    opts_of = {"": options(top)}
    for c in commands:
        opts_of[c] = options(run(rbdem, c, "--help"))
    keys = scene_keys(run(rbdem, "--help-scene"))
    missing_sections = {k.split(".")[0] for k in keys} - set(SECTIONS)
    if missing_sections:
        sys.exit(f"docs_consistency: scene sections {sorted(missing_sections)} are not in SECTIONS: add them")

    problems = []
    pages = [os.path.join(source_dir, "README.md")] + sorted(glob.glob(os.path.join(source_dir, "docs", "*.md")))
    for page in pages:
        with open(page, encoding="utf-8") as f:
            text = f.read()
        rel = os.path.relpath(page, source_dir)
        check_commands(rel, text, commands, opts_of, keys, source_dir, problems)
        if os.path.basename(page) not in SKIP_KEY_CHECK:
            check_keys(rel, text, keys, problems)
    for p in problems:
        print(p)
    print(f"docs_consistency: {len(pages)} pages, {len(commands)} commands, {len(keys)} scene keys: "
          f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
