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

# Percent-encoded buffer URIs (RFC 3986): a valid one names the file beside the glTF and loads;
# encoded dot-dot, slash or NUL and malformed escapes are refused on the decoded name.
escaping = json.load(open(os.path.join(bad_dir, "gltf", "buffer-uri-escapes.gltf")))
shutil.copy(os.path.join(bad_dir, "gltf", "single-hose.bin"),
            os.path.join(generated, "single hose.bin"))
with open(os.path.join(scratch, "secret.bin"), "wb") as f:  # exists, outside bad/generated
    f.write(open(os.path.join(bad_dir, "gltf", "single-hose.bin"), "rb").read())
for name, uri in [("uri-percent-valid", "single%20hose.bin"),
                  ("uri-percent-dot-dot", "%2E%2E/%2E%2E/secret.bin"),
                  ("uri-percent-slash", "..%2F..%2Fsecret.bin"),
                  ("uri-percent-absolute", "%2Fetc%2Fpasswd"),
                  ("uri-percent-malformed", "single%2hose.bin"),
                  ("uri-percent-nul", "single-hose.bin%00.txt")]:
    escaping["buffers"][0]["uri"] = uri
    write(name + ".gltf", json.dumps(escaping))

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


def check(ok, name, detail):
    print(("ok   " if ok else "FAIL ") + name)
    if not ok:
        failures.append(name + ": " + detail)


# Unreadable files. CI runs as root, where chmod 000 does not stop reading, so the commands run
# in a child that first drops to user and group nobody (65534); as any other user chmod 000 is
# enough. A probe checks that the child really cannot read, else the cases would prove nothing.
def run_unprivileged(args, cwd):
    extra = dict(user=65534, group=65534, extra_groups=[]) if os.geteuid() == 0 else {}
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, errors="replace",
                          timeout=300, **extra)


# In a fresh folder under /tmp with its own copy of the CLI: the checkout may sit in a folder
# (e.g. /root) that user nobody cannot even enter.
import atexit, tempfile
locked = tempfile.mkdtemp(prefix="chaintube-unreadable-")
atexit.register(shutil.rmtree, locked, True)
os.chmod(locked, 0o777)  # the unprivileged child may write here: only the inputs are locked
unprivileged_cli = os.path.join(locked, "chaintube")
shutil.copy(chaintube, unprivileged_cli)
locked_project = os.path.join(locked, "project.ctproj")
shutil.copy(sample, locked_project)
locked_glb = os.path.join(locked, "locked.glb")
existing = os.path.join(locked, "existing.glb")
subprocess.run([chaintube, "export", sample, "-o", locked_glb, "-q"], check=True)
subprocess.run([chaintube, "export", sample, "-o", existing, "-q"], check=True)
for name in os.listdir(locked):
    os.chmod(os.path.join(locked, name), 0o755 if name == "chaintube" else 0o644)
os.chmod(locked_project, 0)
os.chmod(locked_glb, 0)
probe = run_unprivileged(["cat", "project.ctproj"], locked)
check(probe.returncode != 0, "unreadable: the unprivileged child cannot read a chmod 000 file",
      "it could (exit %d): the unreadable cases below would prove nothing" % probe.returncode)
for target, message in [("project.ctproj", "project.ctproj: cannot be opened for reading"),
                        ("locked.glb", "locked.glb: cannot be read (missing or no permission)")]:
    result = run_unprivileged([unprivileged_cli, "validate", target], locked)
    check(result.returncode == 1 and message in result.stderr, "unreadable/" + target,
          "expected exit 1 and %r, got exit %d and %r" % (message, result.returncode,
                                                          result.stderr))
def digest_of(folder, names):
    return {n: hashlib.sha256(open(os.path.join(folder, n), "rb").read()).hexdigest()
            for n in names}


kept = ["existing.glb", "existing.hoses.json"]
before = digest_of(locked, kept)
result = run_unprivileged([unprivileged_cli, "export", "project.ctproj", "-o", "existing.glb"],
                          locked)
message = "project.ctproj: cannot be opened for reading"
check(result.returncode == 1 and message in result.stderr and digest_of(locked, kept) == before,
      "unreadable project exported over an existing export: exit 1, the export intact",
      "exit %d, stderr %r, unchanged %s" % (result.returncode, result.stderr,
                                            digest_of(locked, kept) == before))

# A project file being written by another process while we read it: a writer process truncates
# it, writes the first 60 % and holds it open (a non-atomic writer, e.g. another tool); our
# commands see a truncated JSON document and say so, and an existing export is left intact.
# When the writer has finished, the same file reads fine (nothing was cached or damaged).
racing = os.path.join(scratch, "being-written")
os.makedirs(racing)
racing_project = os.path.join(racing, "project.ctproj")
racing_output = os.path.join(racing, "rig.glb")
shutil.copy(sample, racing_project)
subprocess.run([chaintube, "export", racing_project, "-o", racing_output, "-q"], check=True)
kept = ["rig.glb", "rig.hoses.json"]
before = digest_of(racing, kept)
text = open(sample, "rb").read()
writer = subprocess.Popen(
    [sys.executable, "-c",
     "import sys; f = open(sys.argv[1], 'wb'); data = open(sys.argv[2], 'rb').read();"
     "f.write(data[:int(len(data) * 0.6)]); f.flush(); print('half', flush=True);"
     "sys.stdin.readline(); f.write(data[int(len(data) * 0.6):]); f.close()",
     racing_project, sample], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
ready = writer.stdout.readline().strip() == "half"
validate = subprocess.run([chaintube, "validate", racing_project], capture_output=True, text=True,
                          errors="replace", timeout=300)
export = subprocess.run([chaintube, "export", racing_project, "-o", racing_output],
                        capture_output=True, text=True, errors="replace", timeout=300)
writer.stdin.write("finish\n")
writer.stdin.flush()
writer.wait(timeout=60)
message = "project.ctproj: not valid JSON: parse error at line"
check(ready and validate.returncode == 1 and message in validate.stderr and
      "unexpected end of input" in validate.stderr,
      "project being written: validate says the JSON is truncated",
      "exit %d, stderr %r" % (validate.returncode, validate.stderr))
check(export.returncode == 1 and message in export.stderr and digest_of(racing, kept) == before,
      "project being written: export exits 1 and leaves the existing export intact",
      "exit %d, stderr %r" % (export.returncode, export.stderr))
after = subprocess.run([chaintube, "validate", racing_project], capture_output=True, text=True)
check(open(racing_project, "rb").read() == text and after.returncode == 0,
      "project being written: once complete it validates", "exit %d, stderr %r, %d of %d bytes" % (
          after.returncode, after.stderr, len(open(racing_project, "rb").read()), len(text)))

for failure in failures:
    print(failure, file=sys.stderr)
sys.exit(1 if failures else 0)
