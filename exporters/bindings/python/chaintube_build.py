"""The PEP 517 build backend of `pip install .` (pyproject.toml at the repository root).

With scikit-build-core importable (it is not a Debian 12 package), every hook is its own, driven
by pyproject.toml's [tool.scikit-build] table. Without it (this project's machines: nothing is
downloaded) the wheel is built here with the standard library alone: CMake configures the
repository in build-python/ (no editor, no tests, for the running interpreter), builds the
target chaintube_python and the scene-reader programs, and the module, its type stubs and the
readers are packed into the wheel with zipfile. `pip install . --no-build-isolation` uses it
offline.
"""
import base64
import hashlib
import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

try:  # the backend pyproject.toml names, when it is installed
    from scikit_build_core import build as _scikit_build
except ImportError:
    _scikit_build = None

NAME = "chaintube"
VERSION = "0.1.0"
SOURCE = Path(__file__).resolve().parents[3]
READERS = ("chaintube-scene-reader", "chaintube-step-reader")


def get_requires_for_build_wheel(config_settings=None):
    if _scikit_build:
        return _scikit_build.get_requires_for_build_wheel(config_settings)
    return []


def get_requires_for_build_sdist(config_settings=None):
    if _scikit_build:
        return _scikit_build.get_requires_for_build_sdist(config_settings)
    return []


def build_sdist(sdist_directory, config_settings=None):
    if _scikit_build:
        return _scikit_build.build_sdist(sdist_directory, config_settings)
    raise RuntimeError("chaintube_build: an sdist needs scikit-build-core; build a wheel "
                       "(pip install .) or use the git repository")


def _metadata():
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {VERSION}\n"
            "Summary: ChainTube: deformable hoses and cables for VR training scenes\n"
            "Requires-Python: >=3.9\nRequires-Dist: numpy\n")


def _tag():
    interpreter = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{interpreter}-{interpreter}{sys.abiflags}-{platform}"


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    if _scikit_build:
        return _scikit_build.prepare_metadata_for_build_wheel(metadata_directory, config_settings)
    info = Path(metadata_directory) / f"{NAME}-{VERSION}.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text(_metadata())
    return info.name


def _build_module():
    build = SOURCE / "build-python"
    subprocess.run(["cmake", "-S", str(SOURCE), "-B", str(build), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=RelWithDebInfo", "-DCHAINTUBE_SKIP_EDITOR=ON",
                    "-DCHAINTUBE_WARNINGS_AS_ERRORS=ON", f"-DCHAINTUBE_PYTHON={sys.executable}"],
                   check=True, stdout=sys.stderr)
    subprocess.run(["cmake", "--build", str(build), "-j", os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2"),
                    "--target", "chaintube_python", "chaintube_scene_reader",
                    "chaintube_step_reader"], check=True, stdout=sys.stderr)
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    module = build / "exporters" / "bindings" / "python" / f"{NAME}{suffix}"
    if not module.is_file():
        raise RuntimeError(f"chaintube_build: the build made no {module}: is pybind11-dev "
                           f"installed for {sys.executable}?")
    return build, module


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    if _scikit_build:
        return _scikit_build.build_wheel(wheel_directory, config_settings, metadata_directory)
    build, module = _build_module()
    files = {module.name: module.read_bytes(),
             f"{NAME}.pyi": (SOURCE / "exporters/bindings/python/chaintube.pyi").read_bytes()}
    # The module finds the reader programs of scene import in chaintube_readers/ beside it.
    for reader in READERS:
        files[f"chaintube_readers/{reader}"] = (build / "formats" / reader).read_bytes()
    info = f"{NAME}-{VERSION}.dist-info"
    files[f"{info}/METADATA"] = _metadata().encode()
    files[f"{info}/WHEEL"] = (f"Wheel-Version: 1.0\nGenerator: chaintube_build\n"
                              f"Root-Is-Purelib: false\nTag: {_tag()}\n").encode()
    record = []
    for name, data in files.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        record.append(f"{name},sha256={digest},{len(data)}")
    record.append(f"{info}/RECORD,,")
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel = f"{NAME}-{VERSION}-{_tag()}.whl"
    with zipfile.ZipFile(Path(wheel_directory) / wheel, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in files.items():
            entry = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            executable = name.startswith("chaintube_readers/") or name.endswith(".so")
            entry.external_attr = (0o100755 if executable else 0o100644) << 16  # regular file
            entry.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(entry, data)
    return wheel
