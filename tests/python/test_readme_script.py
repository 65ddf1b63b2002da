"""The top README's Python script (batch export and bill of materials) runs as written."""
import csv
import re
import subprocess
import sys

import chaintube
from conftest import SOURCE, copy_samples


def readme_script():
    text = (SOURCE / "README.md").read_text()
    blocks = re.findall(r"```python\n(# batch_export\.py.*?)```", text, re.S)
    assert len(blocks) == 1, "README.md has no (or several) batch_export.py blocks"
    return blocks[0]


def test_the_readme_batch_export_script_exports_the_folder_and_writes_its_bom(tmp_path):
    script = tmp_path / "batch_export.py"
    script.write_text(readme_script())
    assert len(script.read_text().splitlines()) <= 12
    folder = tmp_path / "projects"
    copy_samples(folder, "test-rig", "single-hose")
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, str(script), str(folder), str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "test-rig.ctproj: 2 hoses" in run.stdout
    for name in ("test-rig", "single-hose"):
        assert (out / f"{name}.glb").stat().st_size > 1000
        assert (out / f"{name}.hoses.json").is_file()
    rows = list(csv.DictReader((out / "bom.csv").open()))
    report = chaintube.report(folder)
    assert [row["hose"] for row in rows if row["kind"] == "hose"] == \
        [hose["id"] for hose in report["hoses"]]
    totals = {row["material"]: float(row["cut_length_m"]) for row in rows if row["kind"] == "total"}
    assert totals == {total["material"]: total["cut_length"] for total in report["materials"]}
