// Moving parts (project format 1.4, "motions"): hinges and sliders are saved per node path, read
// back exactly, absent from older files (which load unchanged), refused with precise errors when
// malformed; a motion moves its node and everything under it by the motion's rigid transform,
// and a motion under another travels with it.
#include "chaintube/formats/motion.h"
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "test_files.h"

#include <Eigen/Geometry>
#include <cmath>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <numbers>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

PartMotion hinge(const std::string& id, const std::string& node)
{
    PartMotion motion;
    motion.id = id;
    motion.scene = "rig";
    motion.node = node;
    motion.kind = PartMotion::Kind::Hinge;
    motion.axis = Vec3(0.0, 2.0, 0.0); // not unit: written as given
    motion.point = Vec3(0.1, 0.0, 0.15);
    motion.minimum = -0.5;
    motion.maximum = 1.25;
    return motion;
}

PartMotion slider(const std::string& id, const std::string& node)
{
    PartMotion motion;
    motion.id = id;
    motion.scene = "rig";
    motion.node = node;
    motion.kind = PartMotion::Kind::Slider;
    motion.axis = Vec3(1.0, 0.0, 0.0);
    motion.minimum = 0.0;
    motion.maximum = 0.12;
    return motion;
}

/// The test rig with a hinge on the valve and a slider on the right bracket.
Project rigWithMotions()
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    project.motions = {hinge("valve-turn", "/test-rig/valve"),
                       slider("bracket-slide", "/test-rig/bracket_right")};
    return project;
}

std::string motionError(const json& document)
{
    try {
        parseProject(document.dump(), "moving.ctproj");
    } catch (const ProjectFormatError& error) {
        return error.what();
    }
    ADD_FAILURE() << "accepted: " << document.dump();
    return {};
}

TEST(Motions, AHingeAndASliderRoundTripExactly)
{
    testing::TemporaryFolder folder;
    const Project project = rigWithMotions();
    // Saved beside a copy of the rig's scene, so the relative scene path stays valid.
    fs::create_directories(folder / "scenes");
    fs::copy_file(kSamples / "scenes" / "test-rig.gltf", folder / "scenes" / "test-rig.gltf");
    saveProject(project, folder / "moving.ctproj");
    const json written = json::parse(testing::readText(folder / "moving.ctproj"));
    EXPECT_EQ(written["version"],
              std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor));
    ASSERT_EQ(written["motions"].size(), 2u);
    EXPECT_EQ(written["motions"][0]["kind"], "hinge");
    EXPECT_EQ(written["motions"][0]["axis"], json::array({0.0, 2.0, 0.0}));
    EXPECT_EQ(written["motions"][0]["point"], json::array({0.1, 0.0, 0.15}));
    EXPECT_EQ(written["motions"][0]["min"], -0.5);
    EXPECT_EQ(written["motions"][0]["max"], 1.25);
    EXPECT_EQ(written["motions"][1]["kind"], "slider");
    EXPECT_FALSE(written["motions"][1].contains("point")) << "a slider has no point";
    const Project loaded = loadProject(folder / "moving.ctproj");
    EXPECT_EQ(loaded, project);
    // The canonical text is a fixed point.
    EXPECT_EQ(serialiseProject(loaded), testing::readText(folder / "moving.ctproj"));
}

TEST(Motions, EqualityNoticesEveryField)
{
    const Project base = rigWithMotions();
    const auto changed = [&](auto edit) {
        Project copy = base;
        edit(copy.motions[0]);
        return copy != base;
    };
    EXPECT_TRUE(changed([](PartMotion& m) { m.id = "other"; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.node = "/test-rig"; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.axis.x() = 1e-12; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.point.z() += 1e-12; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.minimum = -0.25; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.maximum = 1.0; }));
    EXPECT_TRUE(changed([](PartMotion& m) { m.kind = PartMotion::Kind::Slider; }));
    // A slider's point is neither written nor compared.
    Project copy = base;
    copy.motions[1].point = Vec3(5, 5, 5);
    EXPECT_EQ(copy, base);
}

TEST(Motions, AFileBefore1_4LoadsUnchangedWithNoMotions)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    json document = json::parse(testing::readText(file));
    document["version"] = "1.3";
    document.erase("motions");
    ProjectLoadReport report;
    const Project old = parseProject(document.dump(), file, {}, &report);
    EXPECT_TRUE(report.migrated);
    EXPECT_EQ(report.fileVersion, "1.3");
    EXPECT_TRUE(old.motions.empty());
    EXPECT_EQ(old, loadProject(file)) << "the 1.3 layout is the 1.4 one without motions";
    // Written back in the current version with an empty motion list.
    const json saved = json::parse(serialiseProject(old));
    EXPECT_EQ(saved["version"],
              std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor));
    EXPECT_EQ(saved["motions"], json::array());
}

TEST(Motions, BadMotionsAreRefusedNamingFileFieldAndExpectation)
{
    const json base = json::parse(serialiseProject(rigWithMotions()));
    const auto with = [&](auto edit) {
        json document = base;
        edit(document["motions"]);
        return motionError(document);
    };
    EXPECT_EQ(with([](json& m) { m[0]["min"] = 0.5; }),
              "moving.ctproj: /motions/0/min: expected min <= 0 (radians; value 0 is the part's "
              "pose in the project and lies in the range), got 0.5");
    EXPECT_EQ(with([](json& m) {
                  m[1]["min"] = 0.0;
                  m[1]["max"] = -0.1;
              }),
              "moving.ctproj: /motions/1/max: expected max > min (metres), got min 0.0 and max "
              "-0.1");
    EXPECT_EQ(with([](json& m) { m[1]["max"] = 0.0; }),
              "moving.ctproj: /motions/1/max: expected max > min (metres), got min 0.0 and max "
              "0.0");
    EXPECT_EQ(with([](json& m) {
                  m[0]["axis"] = json::array({0.0, 0.0, 0.0});
              }),
              "moving.ctproj: /motions/0/axis: expected a non-zero direction (world, length > "
              "1e-9, need not be unit), got length 0.0");
    EXPECT_EQ(with([](json& m) { m[0]["kind"] = "screw"; }),
              "moving.ctproj: /motions/0/kind: expected \"hinge\" (a rotation about an axis "
              "through a point) or \"slider\" (a translation along an axis), got \"screw\"");
    EXPECT_EQ(with([](json& m) { m[0]["max"] = 7.0; }),
              "moving.ctproj: /motions/0/max: expected a number in (-inf, 2pi], got 7.0");
    EXPECT_EQ(with([](json& m) {
                  m[1]["point"] = json::array({0.0, 0.0, 0.0});
              }),
              "moving.ctproj: /motions/1/point: unknown key \"point\" (expected one of: id, "
              "scene, node, kind, axis, min, max)");
    EXPECT_EQ(with([](json& m) { m[0].erase("point"); }),
              "moving.ctproj: /motions/0: missing required key \"point\"");
    EXPECT_EQ(with([](json& m) { m[1]["id"] = "valve-turn"; }),
              "moving.ctproj: /motions/1/id: expected a unique motion id, \"valve-turn\" is used "
              "twice");
    EXPECT_EQ(with([](json& m) { m[1]["node"] = "/test-rig/valve"; }),
              "moving.ctproj: /motions/1/node: expected one motion per node, \"/test-rig/valve\" "
              "of scene \"rig\" has two");
    EXPECT_EQ(with([](json& m) { m[0]["scene"] = "elsewhere"; }),
              "moving.ctproj: /motions/0/scene: expected the id of a scene of this project, got "
              "\"elsewhere\"");
    EXPECT_EQ(with([](json& m) { m[0]["node"] = "valve"; }),
              "moving.ctproj: /motions/0/node: expected a node path starting with '/', got "
              "\"valve\"");
    EXPECT_EQ(with([](json& m) { m = json::object(); }),
              "moving.ctproj: /motions: expected an array, got an object");
    // NaN and infinities cannot be written in JSON; their spellings and overflows are refused.
    std::string text = base.dump();
    const std::string key = "\"max\":0.12";
    ASSERT_NE(text.find(key), std::string::npos);
    for (const char* bad : {"NaN", "Infinity", "1e400"}) {
        std::string broken = text;
        broken.replace(broken.find(key), key.size(), std::string("\"max\":") + bad);
        EXPECT_THROW(parseProject(broken, "moving.ctproj"), ProjectFormatError) << bad;
    }
    json document = base;
    document["motions"][0]["point"][1] = nullptr; // what nlohmann writes for a NaN
    EXPECT_EQ(motionError(document), "moving.ctproj: /motions/0/point/1: expected a number in "
                                     "(-inf, inf), got null");
}

TEST(Motions, SavingAnInvalidMotionThrowsAndWritesNothing)
{
    testing::TemporaryFolder folder;
    Project project = rigWithMotions();
    project.motions[0].scene = "nowhere";
    EXPECT_THROW(saveProject(project, folder / "m.ctproj"), ProjectFormatError);
    project = rigWithMotions();
    project.motions[1].maximum = std::nan("");
    EXPECT_THROW(saveProject(project, folder / "m.ctproj"), ProjectFormatError);
    project = rigWithMotions();
    project.motions[0].axis = Vec3::Zero();
    EXPECT_THROW(saveProject(project, folder / "m.ctproj"), ProjectFormatError);
    EXPECT_FALSE(fs::exists(folder / "m.ctproj"));
}

TEST(Motions, AHingeRotatesAboutItsAxisThroughItsPointAndASliderTranslates)
{
    PartMotion turn = hinge("h", "/n");
    turn.axis = Vec3(0.0, 0.0, 3.0);
    turn.point = Vec3(1.0, 0.0, 0.0);
    const Frame quarter = motionFrame(turn, std::numbers::pi / 2);
    EXPECT_NEAR((quarter.apply(Vec3(2.0, 0.0, 0.0)) - Vec3(1.0, 1.0, 0.0)).norm(), 0.0, 1e-15);
    EXPECT_NEAR((quarter.apply(Vec3(1.0, 0.0, 5.0)) - Vec3(1.0, 0.0, 5.0)).norm(), 0.0, 1e-15)
        << "points on the axis stay";
    EXPECT_NEAR((motionFrame(turn, 0.0).apply(Vec3(0.3, -2.0, 7.0)) - Vec3(0.3, -2.0, 7.0)).norm(),
                0.0, 1e-15);
    PartMotion slide = slider("s", "/n");
    slide.axis = Vec3(0.0, 0.0, -4.0);
    EXPECT_NEAR((motionFrame(slide, 0.25).apply(Vec3(1.0, 2.0, 3.0)) - Vec3(1.0, 2.0, 2.75)).norm(),
                0.0, 1e-15);
    EXPECT_DOUBLE_EQ(motionValueAt(turn, 0.0), -0.5);
    EXPECT_DOUBLE_EQ(motionValueAt(turn, 1.0), 1.25);
    EXPECT_DOUBLE_EQ(motionValueAt(slide, 0.5), 0.06);
}

TEST(Motions, AMotionCarriesItsNodeAndChildrenAndANestedMotionTravelsWithItsParent)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    Project project = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    const ImportedScene& rig = scenes.at("rig");
    const int valve = rig.findNode("/test-rig/valve");
    const int inlet = rig.findNode("/test-rig/valve/valve_inlet");
    const int floor = rig.findNode("/test-rig/floor_plate");
    ASSERT_GE(valve, 0);
    ASSERT_GE(inlet, 0);
    // The valve slides along x; its inlet turns about the world y axis through its own origin.
    PartMotion slide = slider("slide", "/test-rig/valve");
    PartMotion turn = hinge("turn", "/test-rig/valve/valve_inlet");
    turn.axis = Vec3::UnitY();
    turn.point = rig.worldTransform(inlet).topRightCorner<3, 1>();
    project.motions = {slide, turn};
    const PartMotions motions(project, scenes);
    EXPECT_TRUE(motions.carried("rig", valve));
    EXPECT_TRUE(motions.carried("rig", inlet));
    EXPECT_FALSE(motions.carried("rig", floor));
    EXPECT_FALSE(motions.carried("rig", 0));
    EXPECT_FALSE(motions.carried("other", valve));
    EXPECT_EQ(motions.nodeOf(1), inlet);

    ImportedScenes moved = motions.posed();
    motions.apply({0.1, 0.0}, moved);
    const Mat4 valveBefore = rig.worldTransform(valve);
    const Mat4 valveAfter = moved.at("rig").worldTransform(valve);
    EXPECT_NEAR((valveAfter.topRightCorner<3, 1>() - valveBefore.topRightCorner<3, 1>() -
                 Vec3(0.1, 0.0, 0.0))
                    .norm(),
                0.0, 1e-15);
    EXPECT_NEAR((valveAfter.topLeftCorner<3, 3>() - valveBefore.topLeftCorner<3, 3>()).norm(), 0.0,
                1e-15);
    // The inlet rides along, unturned.
    EXPECT_NEAR((moved.at("rig").worldTransform(inlet).topRightCorner<3, 1>() -
                 rig.worldTransform(inlet).topRightCorner<3, 1>() - Vec3(0.1, 0.0, 0.0))
                    .norm(),
                0.0, 1e-15);
    EXPECT_EQ(moved.at("rig").worldTransform(floor), rig.worldTransform(floor));

    // Both at once: the inlet turns about its axis carried 0.1 m along x, so its origin (on
    // the axis) only translates and its rotation is the turn times the rest rotation.
    motions.apply({0.1, 0.7}, moved);
    const Mat4 inletAfter = moved.at("rig").worldTransform(inlet);
    EXPECT_NEAR((inletAfter.topRightCorner<3, 1>() -
                 rig.worldTransform(inlet).topRightCorner<3, 1>() - Vec3(0.1, 0.0, 0.0))
                    .norm(),
                0.0, 1e-14);
    const Eigen::Matrix3d turned = Eigen::AngleAxisd(0.7, Vec3::UnitY()).toRotationMatrix() *
                                   rig.worldTransform(inlet).topLeftCorner<3, 3>();
    EXPECT_NEAR((inletAfter.topLeftCorner<3, 3>() - turned).norm(), 0.0, 1e-14);

    // Back at 0: the project's pose.
    motions.apply({0.0, 0.0}, moved);
    EXPECT_NEAR((moved.at("rig").worldTransform(inlet) - rig.worldTransform(inlet)).norm(), 0.0,
                1e-15);
}

TEST(Motions, AMotionOnAnUnknownNodeIsNamedWhenResolved)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    Project project = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    project.motions = {slider("drawer", "/test-rig/drawer")};
    try {
        const PartMotions motions(project, scenes);
        FAIL() << "accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_EQ(std::string(error.what()),
                  "motion 'drawer' (/motions/0): scene 'rig' has no node '/test-rig/drawer'");
    }
    project.motions = {slider("drawer", "/test-rig/valve")};
    const PartMotions motions(project, scenes);
    ImportedScenes moved = motions.posed();
    EXPECT_THROW(motions.apply({0.1, 0.2}, moved), InvalidArgument);
    EXPECT_THROW(motions.apply({std::nan("")}, moved), InvalidArgument);
}

} // namespace
} // namespace chaintube::formats
