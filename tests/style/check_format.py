#!/usr/bin/env python3
"""Checks that every tracked C and C++ source is formatted as .clang-format says.

    check_format.py REPOSITORY    lists each file clang-format would change; exit 1 if any
    check_format.py --self-test   shows that a misformatted source is caught (exit 1 if not)

clang-format 14 (Debian 12's clang-format-14, installed by build.sh) is the reference: other
major versions lay out a few constructs differently. To fix what the check finds:
    clang-format -i $(git ls-files '*.h' '*.cpp' '*.c')
"""
import shutil
import subprocess
import sys

EXTENSIONS = ("*.h", "*.cpp", "*.c")


def clang_format():
    for name in ("clang-format-14", "clang-format"):
        path = shutil.which(name)
        if path:
            return path
    sys.exit("check_format.py: clang-format not found (install Debian's clang-format-14; "
             "./build.sh installs it)")


def unformatted(executable, repository, files):
    """The files among `files` (relative to `repository`) clang-format would change."""
    changed = []
    for start in range(0, len(files), 50):
        batch = files[start:start + 50]
        result = subprocess.run([executable, "--dry-run", "--Werror", *batch], cwd=repository,
                                capture_output=True, text=True)
        if result.returncode == 0:
            continue
        for line in result.stderr.splitlines():
            # "path:line:column: error: code should be clang-formatted [-Wclang-format-violations]"
            if "clang-format-violations" in line:
                path = line.split(":", 1)[0]
                if path not in changed:
                    changed.append(path)
        if not changed:
            sys.exit(f"check_format.py: clang-format failed in {repository}:\n{result.stderr}")
    return changed


def self_test(executable):
    source = "int  main( ){return 0;}\n"
    result = subprocess.run([executable, "--dry-run", "--Werror", "--assume-filename=probe.cpp"],
                            input=source, capture_output=True, text=True)
    if result.returncode == 0:
        sys.exit("check_format.py --self-test: a misformatted source was not reported")
    print("check_format.py --self-test: a misformatted source is reported")


def main():
    executable = clang_format()
    if sys.argv[1:] == ["--self-test"]:
        self_test(executable)
        return
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    repository = sys.argv[1]
    files = subprocess.run(["git", "ls-files", *EXTENSIONS], cwd=repository, check=True,
                           capture_output=True, text=True).stdout.split()
    if not files:
        sys.exit(f"check_format.py: no tracked sources in {repository}")
    changed = unformatted(executable, repository, files)
    version = subprocess.run([executable, "--version"], capture_output=True,
                             text=True).stdout.strip()
    if changed:
        print(f"{len(changed)} of {len(files)} sources are not formatted ({version}):")
        for path in changed:
            print(f"  {path}")
        print("fix with: clang-format -i $(git ls-files '*.h' '*.cpp' '*.c')")
        sys.exit(1)
    print(f"all {len(files)} tracked sources are formatted ({version})")


if __name__ == "__main__":
    main()
