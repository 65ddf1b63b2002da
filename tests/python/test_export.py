"""Export from Python against the CLI's, and the runtime (Rig) over the export."""
import subprocess

import numpy as np
import pytest

import chaintube


def test_export_from_python_is_byte_identical_to_the_cli_export(rig_project, tmp_path, cli):
    cli_out, python_out = tmp_path / "cli" / "rig.glb", tmp_path / "python" / "rig.glb"
    subprocess.run([str(cli), "export", str(rig_project), "-o", str(cli_out), "-q"], check=True,
                   capture_output=True)
    written = chaintube.export(chaintube.Project.load(rig_project), python_out)
    assert written["hose_count"] == 2
    assert written["gltf_file"] == python_out
    for name in ("rig.glb", "rig.hoses.json"):
        cli_bytes = (cli_out.parent / name).read_bytes()
        assert len(cli_bytes) > 1000
        assert (python_out.parent / name).read_bytes() == cli_bytes, name


def test_an_edit_made_in_python_reaches_the_export(rig_project, tmp_path):
    project = chaintube.Project.load(rig_project)
    plain = chaintube.export(project, tmp_path / "plain.glb")
    project.hose("left-feed").colour = (0.9, 0.1, 0.1, 1.0)
    edited = chaintube.export(project, tmp_path / "edited.glb")
    assert plain["joint_count"] == edited["joint_count"]
    assert (tmp_path / "plain.glb").read_bytes() != (tmp_path / "edited.glb").read_bytes()


def test_the_rig_runs_the_export_and_its_joints_follow_a_moved_part(rig_project, tmp_path):
    chaintube.export(chaintube.Project.load(rig_project), tmp_path / "rig.glb")
    rig = chaintube.Rig.load(tmp_path / "rig.glb")
    assert rig.hose_count == 2
    hose = rig.find_hose("left-feed")
    assert hose >= 0 and rig.hose_id(hose) == "left-feed"
    rig.update()
    poses = rig.joint_poses(hose)
    points = rig.hose_points(hose)
    assert poses["translation"].shape == (17, 3) and poses["rotation"].shape == (17, 4)
    assert poses["node"].shape == (17,)
    # A joint's world transform is its ring's centre: the hose's axis point.
    np.testing.assert_allclose(poses["world_translation"], points, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(poses["world_rotation"], axis=1), 1.0, atol=1e-9)

    valve = rig.find_node("valve")
    assert valve >= 0
    before = points.copy()
    # The valve as the scene places it (samples/scenes/test-rig.gltf), moved 3 cm along -x (towards the left bracket).
    updates = rig.set_node_transform(valve, (-0.03, 0.04, 0.15),
                                     (0.0, 0.3826834323650898, 0.0, 0.9238795325112867))
    assert updates and all(result.status != chaintube.Status.InvalidInput for _, result in updates)
    rig.update()
    after = rig.hose_points(hose)
    np.testing.assert_allclose(after[-1] - before[-1], (-0.03, 0.0, 0.0), atol=1e-6)
    np.testing.assert_allclose(rig.joint_poses(hose)["world_translation"], after, atol=1e-9)
    assert rig.world_positions(hose).dtype == np.float32
    # The frame's time: 1/72 s accepted, a bad one raises naming it and changes nothing.
    assert rig.update(1.0 / 72.0) >= 0
    after = rig.hose_points(hose)
    with pytest.raises(chaintube.InvalidArgument) as raised:
        rig.update(0.5)
    assert "seconds" in str(raised.value)
    np.testing.assert_array_equal(rig.hose_points(hose), after)


def test_loading_a_missing_export_raises_naming_the_file(tmp_path):
    try:
        chaintube.Rig.load(tmp_path / "absent.glb")
    except chaintube.Error as error:
        assert "absent.glb" in str(error)
    else:
        raise AssertionError("Rig.load of a missing file did not raise")
