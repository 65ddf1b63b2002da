"""check() and fit_length() return the data the CLI's `check --sweep --json` and
`check --fit-length --json` print, from the same functions."""
import json
import math
import subprocess

import pytest

import chaintube


def cli_json(cli, *arguments):
    run = subprocess.run([str(cli), "check", *map(str, arguments), "--json", "-q"],
                         capture_output=True, text=True)
    assert run.returncode in (0, 3), run.stderr
    return json.loads(run.stdout)


def test_the_sweep_data_is_the_cli_sweep_report(motion_project, cli):
    swept = chaintube.check(chaintube.Project.load(motion_project), sweep=True, steps=10)
    printed = cli_json(cli, motion_project, "--sweep", "--steps", 10)
    assert swept["motions"] == ["lever", "carriage"]
    assert swept["steps"] == 1 + swept["lead_in_steps"] + 2 * 10
    assert [hose["hose"] for hose in swept["hoses"]] == [hose["id"] for hose in printed["hoses"]]
    for mine, theirs in zip(swept["hoses"], printed["hoses"]):
        radius = theirs["bend"]["smallestRadius"]
        if radius is None:
            assert mine["smallest_bend_radius"] is None
        else:
            assert mine["smallest_bend_radius"] == pytest.approx(radius, rel=1e-12)
            assert mine["smallest_bend_radius_step"]["index"] == theirs["bend"]["step"]
        assert len(mine["objects"]) == len(theirs["objects"])
        for object_mine, object_theirs in zip(mine["objects"], theirs["objects"]):
            assert object_mine["object"] == object_theirs["path"]
            assert object_mine["distance"] == pytest.approx(object_theirs["minDistance"],
                                                            rel=1e-12)
        assert len(mine["bend_radius_series"]) == swept["steps"]


def test_a_project_without_motions_sweeps_nothing(rig_project):
    swept = chaintube.check(chaintube.Project.load(rig_project), sweep=True)
    assert swept["steps"] == 0 and swept["hoses"] == []


def test_the_fit_is_the_cli_fit(rig_project, cli):
    fits = chaintube.fit_length(chaintube.Project.load(rig_project))
    printed = cli_json(cli, rig_project, "--fit-length")
    assert [fit["hose"] for fit in fits] == [hose["id"] for hose in printed["hoses"]]
    for mine, theirs in zip(fits, printed["hoses"]):
        assert mine["valid"] == theirs["valid"]
        assert mine["shortest"] == theirs["shortest"] and mine["longest"] == theirs["longest"]
        assert mine["current_length"] == theirs["length"]
        assert math.isfinite(mine["taut_bound"])
