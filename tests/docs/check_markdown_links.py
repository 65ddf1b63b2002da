#!/usr/bin/env python3
"""Checks that every relative link and image in the repository's Markdown files resolves.

    check_markdown_links.py [REPOSITORY]      check every tracked *.md file (default: this repo)
    check_markdown_links.py --self-test       check the checker on a generated tree

A link is checked when it is relative: inline links and images ([text](target),
![alt](target)), reference definitions ([id]: target) and HTML src/href attributes. Links with a
scheme (https:, mailto:, ...) are not followed. The target must exist as a file or folder inside
the repository (a leading '/' means the repository root, as on GitHub); a '#fragment' on a
Markdown target (or on the file itself, '#fragment' alone) must name one of its headings, slugged
as GitHub does. Code blocks and inline code are skipped. Each broken link is printed as
"file:line: 'target': reason"; the exit status is 1 if any was found, 0 otherwise.

Python 3 standard library only.
"""

import os
import re
import subprocess
import sys
import tempfile
import urllib.parse

FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
INLINE_CODE = re.compile(r"(`+)(?:.+?)\1")
# [text](target "title") or ![alt](target); the target may be in <angle brackets>.
INLINE_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*(<[^>]*>|[^\s()]*(?:\([^\s()]*\)[^\s()]*)*)")
REFERENCE_DEFINITION = re.compile(r"^ {0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
HTML_ATTRIBUTE = re.compile(r"<(?:img|a|source)\b[^>]*?\b(?:src|href)\s*=\s*[\"']([^\"']*)[\"']", re.I)
HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def tracked_markdown(repository):
    """Tracked *.md files (git ls-files); without git, every *.md outside build folders."""
    try:
        listed = subprocess.run(["git", "-C", repository, "ls-files", "-z", "--", "*.md"],
                                check=True, capture_output=True).stdout
        return sorted(name for name in listed.decode("utf-8").split("\0") if name)
    except (OSError, subprocess.CalledProcessError):
        found = []
        for folder, dirs, files in os.walk(repository):
            dirs[:] = [d for d in dirs
                       if not d.startswith((".", "build")) and d != "node_modules"]
            found += [os.path.relpath(os.path.join(folder, f), repository)
                      for f in files if f.endswith(".md")]
        return sorted(found)


def slug(heading):
    """GitHub's anchor of a heading: rendered text, lower case, punctuation dropped, '-' for ' '."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links and images: their text
    text = re.sub(r"<[^>]+>", "", text)                          # inline HTML
    text = text.lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def lines_outside_code(text, blank_inline_code=True):
    """(line number, line) of every line outside fenced code blocks, inline code blanked."""
    fence = None
    for number, line in enumerate(text.splitlines(), 1):
        match = FENCE.match(line)
        if fence is None and match:
            fence = match.group(1)[0] * len(match.group(1))
            continue
        if fence is not None:
            if match and match.group(1).startswith(fence):
                fence = None
            continue
        if blank_inline_code:
            line = INLINE_CODE.sub(lambda m: " " * len(m.group(0)), line)
        yield number, line


def anchors_of(path, cache):
    if path not in cache:
        with open(path, encoding="utf-8") as file:
            text = file.read()
        anchors, seen = set(), {}
        for _, line in lines_outside_code(text, blank_inline_code=False):
            match = HEADING.match(line)
            if not match:
                continue
            base = slug(match.group(2))
            count = seen.get(base, 0)
            seen[base] = count + 1
            anchors.add(base if count == 0 else f"{base}-{count}")
        cache[path] = anchors
    return cache[path]


def links_in(text):
    for number, line in lines_outside_code(text):
        for pattern in (INLINE_LINK, REFERENCE_DEFINITION, HTML_ATTRIBUTE):
            for match in pattern.finditer(line):
                target = match.group(1)
                if target.startswith("<") and target.endswith(">"):
                    target = target[1:-1]
                yield number, target


def check_file(repository, name, anchor_cache):
    """Broken links of one Markdown file as (line, target, reason)."""
    source = os.path.join(repository, name)
    with open(source, encoding="utf-8") as file:
        text = file.read()
    root = os.path.realpath(repository)
    problems = []
    for number, target in links_in(text):
        if not target or SCHEME.match(target) or target.startswith("//"):
            continue
        path_part, _, fragment = target.partition("#")
        path_part = urllib.parse.unquote(path_part.partition("?")[0])
        if path_part.startswith("/"):
            resolved = os.path.join(root, path_part.lstrip("/"))
        elif path_part:
            resolved = os.path.join(os.path.dirname(os.path.join(root, name)), path_part)
        else:
            resolved = os.path.join(root, name)
        resolved = os.path.normpath(resolved)
        if resolved != root and not resolved.startswith(root + os.sep):
            problems.append((number, target, "points outside the repository"))
            continue
        if not os.path.exists(resolved):
            problems.append((number, target, "no such file or folder"))
            continue
        if fragment and resolved.endswith(".md") and os.path.isfile(resolved):
            if urllib.parse.unquote(fragment).lower() not in anchors_of(resolved, anchor_cache):
                problems.append((number, target, f"no heading with the anchor #{fragment}"))
    return problems


def check(repository, out):
    anchor_cache = {}
    broken = 0
    for name in tracked_markdown(repository):
        for number, target, reason in check_file(repository, name, anchor_cache):
            print(f"{name}:{number}: '{target}': {reason}", file=out)
            broken += 1
    return broken


def self_test():
    """The checker finds exactly the broken links of a small generated tree."""
    files = {
        "README.md": "# Top\n\n## Two words, and `code`\n\n"
                     "[ok](docs/guide.md) [ok](docs/) ![ok](docs/picture.png)\n"
                     "[ok anchor](#two-words-and-code) [ok](docs/guide.md#the-guide)\n"
                     "[external](https://example.com/missing.md) [mail](mailto:a@b.c)\n"
                     "`[in code](missing-in-code.md)`\n"
                     "```\n[in a fence](missing-in-fence.md)\n```\n"
                     "[bad](docs/missing.md)\n"
                     "![bad image](docs/missing.png)\n"
                     "[bad anchor](docs/guide.md#no-such-heading)\n"
                     "[outside](../outside.md)\n"
                     "[ref]: docs/also-missing.md\n"
                     "<img src=\"docs/missing.svg\">\n",
        "docs/guide.md": "# The guide\n\n[up](../README.md#top) [root](/README.md)\n",
        "docs/picture.png": "",
    }
    expected = [
        "README.md:12: 'docs/missing.md': no such file or folder",
        "README.md:13: 'docs/missing.png': no such file or folder",
        "README.md:14: 'docs/guide.md#no-such-heading': no heading with the anchor #no-such-heading",
        "README.md:15: '../outside.md': points outside the repository",
        "README.md:16: 'docs/also-missing.md': no such file or folder",
        "README.md:17: 'docs/missing.svg': no such file or folder",
    ]
    with tempfile.TemporaryDirectory() as folder:
        for name, contents in files.items():
            os.makedirs(os.path.join(folder, os.path.dirname(name)), exist_ok=True)
            with open(os.path.join(folder, name), "w", encoding="utf-8") as file:
                file.write(contents)

        class Lines:
            def __init__(self):
                self.lines = []

            def write(self, text):
                self.lines += [line for line in text.splitlines() if line]

        found = Lines()
        check(folder, found)  # not a git repository: every *.md is checked
    if found.lines != expected:
        print("check_markdown_links.py --self-test: expected\n  " + "\n  ".join(expected) +
              "\ngot\n  " + "\n  ".join(found.lines), file=sys.stderr)
        return 1
    print("check_markdown_links.py --self-test: the 6 broken links found, nothing else")
    return 0


def main(arguments):
    if arguments[:1] == ["--self-test"]:
        return self_test()
    repository = arguments[0] if arguments else os.path.join(os.path.dirname(__file__), "..", "..")
    broken = check(repository, sys.stdout)
    if broken:
        print(f"{broken} broken link(s) in Markdown files")
        return 1
    print(f"check_markdown_links.py: every relative link in {len(tracked_markdown(repository))} "
          "Markdown files resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
