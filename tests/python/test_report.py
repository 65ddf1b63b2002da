"""The length and bill-of-materials report, checked against figures computed here from the
project file's own numbers, and against the CLI's `report` and `check` output."""
import csv
import io
import json
import math
import subprocess

import numpy as np
import pytest

import chaintube


def route_length(route):
    return sum(math.dist(a, b) for a, b in zip(route, route[1:]))


def smallest_bend_radius(route):
    """Smallest bend radius of a polyline: at each joint the mean of its two segments over
    2 sin(turn / 2), the turn the angle between the segments."""
    smallest = math.inf
    for a, b, c in zip(route, route[1:], route[2:]):
        u, v = np.subtract(b, a), np.subtract(c, b)
        turn = math.acos(max(-1.0, min(1.0, np.dot(u, v) / np.linalg.norm(u) / np.linalg.norm(v))))
        if turn > 0.0:
            mean = 0.5 * (np.linalg.norm(u) + np.linalg.norm(v))
            smallest = min(smallest, mean / (2.0 * math.sin(turn / 2.0)))
    return smallest


@pytest.fixture(scope="module")
def rig_report(tmp_path_factory):
    from conftest import copy_samples
    project = copy_samples(tmp_path_factory.mktemp("report"), "test-rig")[0]
    return project, json.loads(project.read_text()), chaintube.report(project)


def test_cut_lengths_are_the_route_lengths_plus_the_fittings_allowance(rig_report):
    _, document, report = rig_report
    rows = {row["id"]: row for row in report["hoses"]}
    assert list(rows) == ["left-feed", "right-return"]
    for hose in document["hoses"]:
        # The sample's routes have one point per axis point: each is the hose at rest, so its
        # length is the rest length (the file's "length" says the same).
        rest = route_length(hose["route"])
        assert len(hose["route"]) == hose["segmentCount"] + 1
        row = rows[hose["id"]]
        assert row["rest_length"] == pytest.approx(rest, abs=1e-9)
        assert row["fittings_allowance"] == hose["fittingsAllowance"]
        assert row["cut_length"] == pytest.approx(rest + hose["fittingsAllowance"], abs=1e-9)
        assert row["material"] == hose["material"]
        assert row["attachments"] == len(hose["attachments"]) and row["clips"] == 0
    # Hand-computed: 0.48100729 + 0.06 and 0.43341544 + 0.045.
    assert rows["left-feed"]["cut_length"] == pytest.approx(0.5410073, abs=1e-7)
    assert rows["right-return"]["cut_length"] == pytest.approx(0.4784154, abs=1e-7)


def test_bend_radius_and_margin_are_those_of_the_laid_route(rig_report):
    _, document, report = rig_report
    presets = {preset["name"]: preset for preset in document["materialPresets"]}
    for hose, row in zip(document["hoses"], report["hoses"]):
        radius = smallest_bend_radius(hose["route"])
        limit = presets[hose["material"]]["bendLimit"]["minBendRadius"]
        assert row["smallest_bend_radius"] == pytest.approx(radius, rel=1e-6)
        assert row["min_bend_radius"] == limit
        assert row["bend_margin"] == pytest.approx(radius - limit, abs=1e-6)


def test_slack_is_the_rest_length_over_the_shortest_valid_length(rig_report):
    project, _, report = rig_report
    fits = {fit["hose"]: fit for fit in chaintube.fit_length(chaintube.Project.load(project))}
    for row in report["hoses"]:
        fit = fits[row["id"]]
        assert fit["valid"], fit["reason"]
        assert row["shortest_valid_length"] == fit["shortest"]
        assert row["slack"] == pytest.approx(row["rest_length"] - fit["shortest"], abs=1e-12)
        assert fit["taut_bound"] <= row["shortest_valid_length"] <= row["rest_length"] + 1e-9


def test_smallest_clearance_is_the_clearance_checks_nearest_object(rig_report):
    project, _, report = rig_report
    found = chaintube.check(chaintube.Project.load(project), sweep=False, clearance=1.0)
    for row in report["hoses"]:
        nearest = min((v for v in found["violations"] if v["hose"] == row["id"]),
                      key=lambda v: v["distance"])
        if nearest["distance"] < 0.05:  # the report searches objects within 5 cm
            assert row["smallest_clearance"] == pytest.approx(nearest["distance"], abs=1e-9)
            assert row["clearance_object"] == f"{nearest['scene']}:{nearest['object']}"
            assert row["clearance_axis_point"] == nearest["axis_point"]
            np.testing.assert_allclose(row["clearance_point"], nearest["on_hose"], atol=1e-9)
            assert row["clearance_motion"] == "project pose"
        else:
            assert row["smallest_clearance"] is None


def test_totals_per_material_sum_the_hoses_of_each_material(motion_project):
    from conftest import copy_samples
    rig = copy_samples(motion_project.parent, "test-rig")[0]
    report = chaintube.report([rig, motion_project], fit_length=False)
    assert len(report["hoses"]) == 5
    for total in report["materials"]:
        rows = [row for row in report["hoses"] if row["material"] == total["material"]]
        assert total["hoses"] == len(rows)
        assert total["cut_length"] == pytest.approx(sum(row["cut_length"] for row in rows))
    cables = next(t for t in report["materials"] if t["material"] == "cable bundle")
    motion = json.loads(motion_project.read_text())
    expected = sum(route_length(h["route"]) for h in motion["hoses"]
                   if h["material"] == "cable bundle")
    assert cables["hoses"] == 2
    assert cables["cut_length"] == pytest.approx(expected, abs=1e-9)
    motion_rows = [row for row in report["hoses"] if row["project"] == str(motion_project)]
    assert len(motion_rows) == 3
    assert all(row["fit_note"] == "not fitted" and row["slack"] is None for row in motion_rows)
    # Over motions the clearance names the motion values where it occurs.
    for row in motion_rows:
        if row["smallest_clearance"] is not None:
            assert "lever" in row["clearance_motion"] and "carriage" in row["clearance_motion"]


def test_the_cli_report_is_the_text_of_the_same_report(rig_report, cli):
    project, _, report = rig_report
    for form in ("csv", "json", "md"):
        printed = subprocess.run([str(cli), "report", str(project), "--format", form, "-q"],
                                 check=True, capture_output=True, text=True).stdout
        assert printed == chaintube.report(chaintube.Project.load(project), format=form)
    rows = list(csv.DictReader(io.StringIO(chaintube.report(project, format="csv"))))
    hose_rows = [row for row in rows if row["kind"] == "hose"]
    assert [float(row["cut_length_m"]) for row in hose_rows] == \
        [row["cut_length"] for row in report["hoses"]]
    assert [row["material"] for row in rows if row["kind"] == "total"] == \
        [total["material"] for total in report["materials"]]


def test_the_cli_report_of_a_missing_project_fails_naming_it(cli, tmp_path):
    run = subprocess.run([str(cli), "report", str(tmp_path / "absent.ctproj")],
                         capture_output=True, text=True)
    assert run.returncode == 1
    assert "absent.ctproj" in run.stderr and "no such file or folder" in run.stderr
    run = subprocess.run([str(cli), "report", str(tmp_path), "--format", "pdf"],
                         capture_output=True, text=True)
    assert run.returncode == 2


def test_export_writes_the_report_beside_each_export_on_request(rig_report, cli, tmp_path):
    project, _, _ = rig_report
    subprocess.run([str(cli), "export", str(project), "-o", str(tmp_path / "one" / "rig.glb"),
                    "--report", "json", "-q"], check=True, capture_output=True)
    beside = json.loads((tmp_path / "one" / "rig.report.json").read_text())
    assert beside == json.loads(chaintube.report(project, format="json"))
    subprocess.run([str(cli), "export", "--batch", str(project.parent), "-o",
                    str(tmp_path / "batch"), "--report", "csv", "-q"], check=True,
                   capture_output=True)
    assert (tmp_path / "batch" / "test-rig.report.csv").read_text() == \
        chaintube.report(project, format="csv")
    run = subprocess.run([str(cli), "export", str(project), "--report", "xls"],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "--report" in run.stderr
