#!/usr/bin/env python3
"""Replays tests/data/bad/expected.json: runs `chaintube validate FILE` on every case and checks
the exit code and that stderr contains the expected message. Cases under generated/ are made
here first (too big for git, or symbolic links and folders). Then injects a full disk during
`chaintube export` over an existing export and checks that the old files are left intact.

usage: replay_bad_inputs.py CHAINTUBE BAD_DIR SCRATCH_DIR SAMPLE_PROJECT
"""
import hashlib, json, os, shutil, subprocess, sys

chaintube, bad_dir, scratch, sample = [os.path.abspath(a) for a in sys.argv[1:5]]
shutil.rmtree(scratch, ignore_errors=True)
work = os.path.join(scratch, "bad")
shutil.copytree(bad_dir, work, symlinks=True)
generated = os.path.join(work, "generated")
os.makedirs(generated)
sample_doc = json.load(open(sample))


def write(name, text):
    with open(os.path.join(generated, name), "w") as f:
        f.write(text)


def project_with_hoses(hoses):
    doc = dict(sample_doc)
    doc["hoses"] = hoses
    return doc


write("deeply-nested.ctproj", '{"format": ' + "[" * 100000 + "]" * 100000 + "}")
# 10^7 hoses: refused while parsing, before a DOM of 10^7 objects exists.
with open(os.path.join(generated, "ten-million-hoses.ctproj"), "w") as f:
    f.write('{"format": "chaintube-project", "version": "1.0", "hoses": [')
    f.write(",".join(["{}"] * 10_000_000))
    f.write("]}")
write("too-many-hoses.ctproj", json.dumps(project_with_hoses([{}] * 100001)))
# 1,001 hoses of 10^6 segments each: 10^9 axis points.
hose = dict(sample_doc["hoses"][0])
hose["segmentCount"] = 1000000
hoses = []
for i in range(1001):
    h = dict(hose)
    h["id"] = "h%d" % i
    hoses.append(h)
write("billion-points.ctproj", json.dumps(project_with_hoses(hoses)))
os.mkdir(os.path.join(generated, "directory.ctproj"))
os.symlink("symlink-loop.ctproj", os.path.join(generated, "symlink-loop.ctproj"))
os.symlink("loop.glb", os.path.join(generated, "loop.glb"))
doc = dict(sample_doc)
doc["scenes"] = [{"id": "s", "path": "loop.glb",
                  "import": {"chordalTolerance": 0.0001, "angularTolerance": 0.5}}]
write("scene-symlink-loop.ctproj", json.dumps(doc))
write("unknown.txt", "hello")

failures = []
manifest = json.load(open(os.path.join(bad_dir, "expected.json")))
for case in manifest["cases"]:
    result = subprocess.run([chaintube, "validate", case["file"]], cwd=work,
                            capture_output=True, text=True, errors="replace", timeout=300)
    ok = result.returncode == case["exit"] and case["message"] in result.stderr
    print(("ok   " if ok else "FAIL ") + case["file"] + ": exit %d" % result.returncode)
    if not ok:
        failures.append("%s: expected exit %d and %r, got exit %d and stderr:\n%s" % (
            case["file"], case["exit"], case["message"], result.returncode, result.stderr))

# A disk that fills up during export (RLIMIT_FSIZE: writes beyond 8 KiB fail with EFBIG): the
# command fails with exit 1 naming the cause, and the previous export (.glb + .hoses.json) is
# left byte for byte as it was, so it still validates.
export_dir = os.path.join(scratch, "disk-full")
os.makedirs(export_dir)
output = os.path.join(export_dir, "rig.glb")
subprocess.run([chaintube, "export", sample, "-o", output, "-q"], check=True)
changed = dict(sample_doc)
changed["hoses"] = [dict(sample_doc["hoses"][0], segmentCount=10)]
changed_file = os.path.join(export_dir, "changed.ctproj")
json.dump(changed, open(changed_file, "w"))
digest = lambda: {n: hashlib.sha256(open(os.path.join(export_dir, n), "rb").read()).hexdigest()
                  for n in sorted(os.listdir(export_dir))}
before = digest()
result = subprocess.run(["sh", "-c", 'ulimit -f 8; trap "" XFSZ; exec "$0" export "$1" -o "$2"',
                         chaintube, changed_file, output], capture_output=True, text=True)
after = digest()
ok = result.returncode == 1 and "File too large" in result.stderr and before == after
print(("ok   " if ok else "FAIL ") + "export onto a full disk leaves the previous export intact")
if not ok:
    failures.append("disk-full export: exit %d, stderr %r, files before %s after %s" % (
        result.returncode, result.stderr, before, after))
if subprocess.run([chaintube, "validate", output], capture_output=True).returncode != 0:
    failures.append("disk-full export: the previous export no longer validates")

for failure in failures:
    print(failure, file=sys.stderr)
sys.exit(1 if failures else 0)
