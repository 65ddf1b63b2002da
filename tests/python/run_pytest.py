"""Runs `python -m pytest <folder> -q` for ctest; exit 77 (ctest: skipped) without pytest or NumPy."""
import importlib.util
import subprocess
import sys

missing = [name for name in ("pytest", "numpy") if importlib.util.find_spec(name) is None]
if missing:
    print(f"{', '.join(missing)} not installed for {sys.executable}: the Python tests are skipped")
    sys.exit(77)
sys.exit(subprocess.call([sys.executable, "-m", "pytest", sys.argv[1], "-q",
                          "-p", "no:cacheprovider"]))
