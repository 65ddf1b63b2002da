"""Projects from Python: load, edit, validate, save, and the errors bad files raise."""
import json

import pytest

import chaintube


def test_load_edit_save_load_gives_back_the_edited_project(rig_project, tmp_path):
    project = chaintube.Project.load(rig_project)
    assert [hose.id for hose in project.hoses] == ["left-feed", "right-return"]
    hose = project.hose("left-feed")
    hose.name = "left feed, re-routed"
    hose.length = hose.length + 0.02
    hose.fittings_allowance = 0.08
    hose.material = chaintube.Material(0.03, min_bend_radius=0.09)
    hose.attachments[1].translation = (0.0, 0.001, 0.0)
    project.motions.append(chaintube.Motion())
    motion = project.motions[0]
    motion.id, motion.scene, motion.node = "valve-turn", "rig", "/test-rig/valve"
    motion.kind, motion.axis, motion.minimum, motion.maximum = "hinge", (0, 1, 0), -0.2, 0.3
    edited_length = hose.length

    target = rig_project.parent / "edited.ctproj"
    project.save(target)
    assert project.path == target
    again = chaintube.Project.load(target)
    assert again == project
    left = again.hose("left-feed")
    assert left.name == "left feed, re-routed"
    assert left.length == edited_length
    assert left.fittings_allowance == 0.08
    assert left.material == chaintube.Material(0.03, min_bend_radius=0.09)
    assert tuple(left.attachments[1].translation) == (0.0, 0.001, 0.0)
    assert again.motions[0].kind == "hinge" and again.motions[0].minimum == -0.2
    # The file is the canonical text, in the current format version, with the new field.
    text = target.read_text()
    assert text == again.to_json()
    document = json.loads(text)
    assert document["version"] == "1.7"
    assert document["hoses"][0]["fittingsAllowance"] == 0.08
    assert "fittingsAllowance" in document["hoses"][1]  # the sample's own allowance


def test_an_edit_the_loader_would_refuse_raises_naming_the_field_and_saves_nothing(rig_project):
    project = chaintube.Project.load(rig_project)
    project.hoses[1].length = -0.5
    with pytest.raises(chaintube.ProjectFormatError) as raised:
        project.validate()
    assert raised.value.json_pointer == "/hoses/1/length"
    assert "/hoses/1/length" in str(raised.value)
    target = rig_project.parent / "refused.ctproj"
    with pytest.raises(chaintube.ProjectFormatError) as raised:
        project.save(target)
    assert raised.value.json_pointer == "/hoses/1/length"
    assert not target.exists()


def test_a_negative_fittings_allowance_is_refused(rig_project):
    project = chaintube.Project.load(rig_project)
    project.hoses[0].fittings_allowance = -0.01
    with pytest.raises(chaintube.ProjectFormatError) as raised:
        project.validate()
    assert raised.value.json_pointer == "/hoses/0/fittingsAllowance"


def test_a_malformed_file_raises_naming_the_file_the_field_and_the_expectation(rig_project):
    document = json.loads(rig_project.read_text())
    document["hoses"][1]["outerDiameter"] = "wide"
    bad = rig_project.parent / "bad-diameter.ctproj"
    bad.write_text(json.dumps(document))
    with pytest.raises(chaintube.ProjectFormatError) as raised:
        chaintube.Project.load(bad)
    error = raised.value
    assert isinstance(error, chaintube.FileError) and isinstance(error, chaintube.Error)
    assert error.file.endswith("bad-diameter.ctproj")
    assert error.json_pointer == "/hoses/1/outerDiameter"
    assert "expected" in error.expected
    assert str(error).startswith(error.file + ": /hoses/1/outerDiameter: expected")


def test_a_missing_file_raises_a_file_error_naming_it(tmp_path):
    with pytest.raises(chaintube.FileError) as raised:
        chaintube.Project.load(tmp_path / "absent.ctproj")
    assert raised.value.file.endswith("absent.ctproj")
    assert "absent.ctproj" in str(raised.value)


def test_invalid_values_raise_invalid_argument_which_is_a_value_error():
    with pytest.raises(chaintube.InvalidArgument) as raised:
        chaintube.Material(expansion_coefficient=1.5)
    assert isinstance(raised.value, ValueError)
    assert "expansion" in str(raised.value).lower()
