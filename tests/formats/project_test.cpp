// The project document: precise errors, versions, migration, canonical round trips, atomic save.
#include "chaintube/formats/project.h"
#include "test_files.h"

#include <cmath>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <random>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::TemporaryFolder;

/// A small valid project with one scene, one preset hose and one inline-material hose.
Project exampleProject()
{
    Project project = Project::withStandardPresets("example");
    project.scenes.push_back({"rig", "scenes/rig.gltf", {}});
    HoseDefinition first;
    first.id = "a";
    first.name = "first";
    first.route = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
    first.material = PresetName{"rubber hose"};
    first.attachments.push_back({"rig", "/rig/bracket", Frame::identity(), 0, 1});
    project.hoses.push_back(first);
    HoseDefinition second = first;
    second.id = "b";
    second.material = Material{0.2, BendLimit::deflectionAngle(0.5)};
    second.attachments.clear();
    project.hoses.push_back(second);
    return project;
}

json exampleJson()
{
    return json::parse(serialiseProject(exampleProject()));
}

/// The message of the ProjectFormatError that parsing `document` throws.
std::string loadError(const json& document, const std::string& name = "engine.ctproj")
{
    try {
        parseProject(document.dump(), name);
    } catch (const ProjectFormatError& error) {
        return error.what();
    }
    ADD_FAILURE() << "accepted: " << document.dump();
    return {};
}

TEST(ProjectReader, OutOfRangeNumberNamesFilePointerAndExpectation)
{
    json document = exampleJson();
    document["hoses"][1]["material"]["expansionCoefficient"] = 1.5;
    EXPECT_EQ(loadError(document),
              "engine.ctproj: /hoses/1/material/expansionCoefficient: expected a number in "
              "[0, 1), got 1.5");
}

TEST(ProjectReader, WrongTypeIsReportedWithWhatWasGot)
{
    json document = exampleJson();
    document["hoses"][0]["outerDiameter"] = "20mm";
    EXPECT_EQ(loadError(document), "engine.ctproj: /hoses/0/outerDiameter: expected a number in "
                                   "(0, inf), got \"20mm\"");
}

TEST(ProjectReader, NonFiniteAndOverflowingNumbersAreRefused)
{
    std::string text = exampleJson().dump();
    const std::string key = "\"roughness\":0.5";
    ASSERT_NE(text.find(key), std::string::npos);
    for (const char* bad : {"1e400", "NaN", "Infinity", "-1e999"}) {
        std::string broken = text;
        broken.replace(broken.find(key), key.size(), std::string("\"roughness\":") + bad);
        EXPECT_THROW(parseProject(broken, "x.ctproj"), ProjectFormatError) << bad;
    }
    json document = exampleJson();
    document["hoses"][0]["route"][1][0] = 1e308 * 10; // +inf is written as null by nlohmann
    EXPECT_THROW(parseProject(document.dump(), "x.ctproj"), ProjectFormatError);
}

TEST(ProjectReader, MalformedJsonGivesLineAndColumn)
{
    try {
        parseProject("{\n  \"format\": \"chaintube-project\",\n  oops\n}", "broken.ctproj");
        FAIL();
    } catch (const ProjectFormatError& error) {
        EXPECT_NE(std::string(error.what()).find("broken.ctproj: not valid JSON: "),
                  std::string::npos);
        EXPECT_NE(std::string(error.what()).find("line 3"), std::string::npos) << error.what();
    }
}

TEST(ProjectReader, UnknownKeyIsRefusedListingTheKnownOnes)
{
    json document = exampleJson();
    document["hoses"][0]["diameter"] = 0.02;
    const std::string message = loadError(document);
    EXPECT_NE(message.find("/hoses/0/diameter: unknown key \"diameter\" (expected one of: id, "),
              std::string::npos)
        << message;
}

TEST(ProjectReader, CrossReferencesAreChecked)
{
    json document = exampleJson();
    document["hoses"][1]["id"] = "a";
    EXPECT_NE(loadError(document).find("/hoses/1/id: expected a unique hose id"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["material"] = "titanium hose";
    EXPECT_NE(loadError(document).find("/hoses/0/material: expected the name of a material preset"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["attachments"][0]["scene"] = "elsewhere";
    EXPECT_NE(loadError(document).find("/hoses/0/attachments/0/scene: expected the id of a scene"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["attachments"].push_back(document["hoses"][0]["attachments"][0]);
    EXPECT_NE(loadError(document).find("/hoses/0/attachments/1/points: expected a point range not "
                                       "overlapping another attachment's [0, 1]"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["attachments"][0]["points"] = json::array({0, 13});
    EXPECT_NE(loadError(document).find("/hoses/0/attachments/0/points/1: expected an integer in "
                                       "[0, 12], got 13"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["attachments"][0]["offset"]["rotation"] = json::array({0, 0, 0, 0.5});
    EXPECT_NE(loadError(document).find("/hoses/0/attachments/0/offset/rotation: expected a unit "
                                       "quaternion"),
              std::string::npos);

    document = exampleJson();
    document["hoses"][0]["route"][1] = document["hoses"][0]["route"][0];
    EXPECT_NE(loadError(document).find("/hoses/0/route/1: expected a route point distinct"),
              std::string::npos);
}

TEST(ProjectReader, NewerMajorVersionIsAClearError)
{
    json document = exampleJson();
    document["version"] = "2.0";
    const std::string message = loadError(document);
    EXPECT_NE(message.find("engine.ctproj: /version: this file was written in project format 2.0, "
                           "newer than this ChainTube understands (up to 1.x)"),
              std::string::npos)
        << message;
}

TEST(ProjectReader, NewerMinorVersionLoadsIgnoringAndReportingUnknownKeys)
{
    json document = exampleJson();
    document["version"] = "1." + std::to_string(kProjectFormatMinor + 1);
    document["hoses"][0]["temperatureRating"] = 120;
    ProjectLoadReport report;
    const Project project = parseProject(document.dump(), "x.ctproj", {}, &report);
    EXPECT_EQ(project, exampleProject());
    EXPECT_EQ(report.ignoredKeys, std::vector<std::string>{"/hoses/0/temperatureRating"});
}

TEST(ProjectReader, WrongFormatOrVersionSyntaxIsRefused)
{
    json document = exampleJson();
    document["format"] = "something-else";
    EXPECT_NE(loadError(document).find("/format: expected \"chaintube-project\""),
              std::string::npos);
    document = exampleJson();
    document["version"] = "1";
    EXPECT_NE(loadError(document).find("/version: expected a version \"<major>.<minor>\""),
              std::string::npos);
}

TEST(ProjectMigration, Version0_9MillimetreDiameterAndHexColourBecome1_0)
{
    json document = exampleJson();
    document["version"] = "0.9";
    for (json& hose : document["hoses"]) {
        hose.erase("outerDiameter");
        hose.erase("colour");
        hose["diameterMm"] = 20;
        hose["color"] = "#336699";
    }
    ProjectLoadReport report;
    const Project project = parseProject(document.dump(), "old.ctproj", {}, &report);
    EXPECT_TRUE(report.migrated);
    EXPECT_EQ(report.fileVersion, "0.9");
    ASSERT_EQ(project.hoses.size(), 2u);
    EXPECT_DOUBLE_EQ(project.hoses[0].outerDiameter, 0.02);
    EXPECT_DOUBLE_EQ(project.hoses[0].colour.r, 0x33 / 255.0);
    EXPECT_DOUBLE_EQ(project.hoses[0].colour.b, 0x99 / 255.0);
    EXPECT_DOUBLE_EQ(project.hoses[0].colour.a, 1.0);
    // Saving writes the current version.
    EXPECT_EQ(json::parse(serialiseProject(project))["version"],
              std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor));
}

TEST(ProjectMigration, BadOldValueIsReportedAtItsOldPointer)
{
    json document = exampleJson();
    document["version"] = "0.9";
    document["hoses"][1]["color"] = "blue";
    document["hoses"][1].erase("colour");
    EXPECT_NE(loadError(document).find("/hoses/1/color: expected a colour \"#RRGGBB\""),
              std::string::npos);
}

TEST(ProjectReader, SceneEscapingTheProjectFolderIsRefusedAtLoad)
{
    TemporaryFolder folder;
    json document = exampleJson();
    document["scenes"][0]["path"] = "../../etc/passwd";
    try {
        parseProject(document.dump(), folder / "p.ctproj");
        FAIL();
    } catch (const ProjectFormatError& error) {
        EXPECT_EQ(error.jsonPointer(), "/scenes/0/path");
        EXPECT_NE(error.expected().find("leaves the project's folder"), std::string::npos);
    }
}

// --- round trips -----------------------------------------------------------------------------

/// Projects with every kind of value, random but reproducible.
Project randomProject(std::mt19937& random)
{
    std::uniform_real_distribution<double> unit(0.0, 1.0), coordinate(-10.0, 10.0);
    std::uniform_int_distribution<int> small(0, 4);
    Project project = Project::withStandardPresets("random " + std::to_string(random()));
    const int sceneCount = small(random);
    for (int s = 0; s < sceneCount; ++s) {
        SceneReference scene{
            "scene-" + std::to_string(s), "scenes/s" + std::to_string(s) + ".glb", {}};
        if (unit(random) < 0.5) scene.import.metresPerUnit = unit(random) + 1e-3;
        if (unit(random) < 0.5)
            scene.import.upAxis = unit(random) < 0.5 ? UpAxis::PositiveY : UpAxis::PositiveZ;
        scene.import.chordalTolerance = 1e-5 + unit(random) * 1e-3;
        if (unit(random) < 0.5) scene.import.placement = Vec3(coordinate(random), 0.0, -1.5);
        scene.import.angularTolerance = 0.1 + unit(random);
        project.scenes.push_back(scene);
    }
    project.materialPresets.push_back(
        {"custom ü \"quoted\"", "line\nbreak",
         Material{unit(random) * 0.99, BendLimit::minBendRadius(unit(random))}});
    const int hoseCount = small(random) * 3;
    for (int h = 0; h < hoseCount; ++h) {
        HoseDefinition hose;
        hose.id = "hose/" + std::to_string(h);
        hose.name = "hose " + std::to_string(h);
        const int points = 2 + small(random);
        for (int p = 0; p < points; ++p)
            hose.route.push_back(Vec3(coordinate(random), coordinate(random), coordinate(random)));
        if (unit(random) < 0.5)
            hose.material = PresetName{project.materialPresets[size_t(small(random))].name};
        else
            hose.material =
                Material{unit(random) * 0.99, unit(random) < 0.5
                                                  ? BendLimit::deflectionAngle(unit(random) * 3)
                                                  : BendLimit::minBendRadius(unit(random))};
        switch (small(random)) {
        case 0:
            hose.profile.shape = Profile::Shape::Circle;
            hose.profile.sides = 3 + small(random) * 7;
            break;
        case 1:
            hose.profile.shape = Profile::Shape::Ellipse;
            hose.profile.semiAxisX = 0.01 + unit(random);
            hose.profile.semiAxisY = 0.01 + unit(random);
            hose.profile.sides = 8;
            break;
        case 2:
            hose.profile.shape = Profile::Shape::Rectangle;
            hose.profile.width = 0.01 + unit(random);
            hose.profile.height = 0.01 + unit(random);
            break;
        case 3:
            hose.profile.shape = Profile::Shape::RoundedRectangle;
            hose.profile.width = 0.02;
            hose.profile.height = 0.01;
            hose.profile.cornerRadius = 0.0049 * unit(random) + 1e-4;
            hose.profile.cornerSegments = 1 + small(random);
            break;
        default:
            hose.profile.shape = Profile::Shape::Polygon;
            hose.profile.points = {Vec2(0, 0), Vec2(unit(random) + 0.1, 0),
                                   Vec2(0, unit(random) + 0.1)};
            hose.profile.smoothAngle = unit(random);
            break;
        }
        hose.outerDiameter = 1e-3 + unit(random) * 0.1;
        if (unit(random) < 0.5)
            hose.segmentCount = 1 + small(random) * 10;
        else {
            hose.segmentCount = 0;
            hose.segmentLength = 1e-3 + unit(random) * 0.1;
        }
        hose.colour = {unit(random), unit(random), unit(random), unit(random)};
        hose.roughness = unit(random);
        if (unit(random) < 0.5) hose.length = 1e-3 + unit(random) * 5.0;
        if (!project.scenes.empty() && hose.segmentCount >= 2) {
            const Quat rotation = Quat(Eigen::AngleAxisd(
                unit(random) * 6, Vec3(unit(random), unit(random), 1).normalized()));
            hose.attachments.push_back({project.scenes[0].id, "/root/part " + std::to_string(h),
                                        Frame{rotation, Vec3(coordinate(random), 0, 1e-7)}, 0, 1});
            hose.attachments.push_back({project.scenes.back().id, "/root/other", Frame::identity(),
                                        hose.segmentCount, hose.segmentCount});
        }
        project.hoses.push_back(hose);
    }
    const int motionCount = project.scenes.empty() ? 0 : small(random);
    for (int m = 0; m < motionCount; ++m) {
        PartMotion motion;
        motion.id = "motion " + std::to_string(m);
        motion.scene = project.scenes[size_t(m) % project.scenes.size()].id;
        motion.node = "/root/moving/" + std::to_string(m);
        motion.kind = unit(random) < 0.5 ? PartMotion::Kind::Hinge : PartMotion::Kind::Slider;
        motion.axis = Vec3(coordinate(random), coordinate(random), 1e-3 + unit(random));
        if (motion.kind == PartMotion::Kind::Hinge)
            motion.point = Vec3(coordinate(random), coordinate(random), coordinate(random));
        motion.minimum = -unit(random) * 6.0;
        motion.maximum = unit(random) * 6.0 + 1e-9;
        project.motions.push_back(motion);
    }
    project.exportSettings = {unit(random) < 0.5 ? "glb" : "gltf",
                              unit(random) < 0.5 ? "" : "out/x.glb", unit(random) < 0.5};
    return project;
}

TEST(ProjectRoundTrip, SaveThenLoadReproducesRandomProjectsExactly)
{
    TemporaryFolder folder;
    std::mt19937 random(12345);
    for (int i = 0; i < 200; ++i) {
        const Project original = randomProject(random);
        saveProject(original, folder / "r.ctproj");
        const Project loaded = loadProject(folder / "r.ctproj");
        ASSERT_EQ(loaded, original) << "project " << i << ":\n" << serialiseProject(original);
        // …and the canonical text is a fixed point.
        saveProject(loaded, folder / "again.ctproj");
        ASSERT_EQ(testing::readText(folder / "again.ctproj"),
                  testing::readText(folder / "r.ctproj"));
    }
}

TEST(ProjectRoundTrip, EqualityNoticesEveryKindOfChange)
{
    const Project base = exampleProject();
    Project changed = base;
    changed.hoses[0].route[1].x() += 1e-12;
    EXPECT_NE(changed, base);
    changed = base;
    changed.hoses[0].attachments[0].offset.rotation = Quat(0, 1, 0, 0);
    EXPECT_NE(changed, base);
    changed = base;
    changed.scenes[0].import.upAxis = UpAxis::PositiveZ;
    EXPECT_NE(changed, base);
    changed = base;
    changed.materialPresets[2].material.expansionCoefficient = 0.3;
    EXPECT_NE(changed, base);
    changed = base;
    changed.hoses[1].length = 1.25;
    EXPECT_NE(changed, base);
    changed = base;
    changed.scenes[0].import.placement = Vec3(0.0, 0.0, 1e-9);
    EXPECT_NE(changed, base);
    changed = base;
    changed.motions.push_back({"m", "rig", "/rig/bracket", PartMotion::Kind::Slider, Vec3::UnitX(),
                               Vec3::Zero(), 0.0, 0.1});
    EXPECT_NE(changed, base);
}

TEST(ProjectSave, InvalidProjectIsRefusedAndTheOldFileKept)
{
    TemporaryFolder folder;
    saveProject(exampleProject(), folder / "p.ctproj");
    const std::string before = testing::readText(folder / "p.ctproj");
    Project broken = exampleProject();
    broken.hoses[0].outerDiameter = std::nan("");
    EXPECT_THROW(saveProject(broken, folder / "p.ctproj"), ProjectFormatError);
    broken = exampleProject();
    broken.hoses[1].material = Material{1.5, BendLimit{}};
    EXPECT_THROW(saveProject(broken, folder / "p.ctproj"), ProjectFormatError);
    EXPECT_EQ(testing::readText(folder / "p.ctproj"), before);
}

TEST(ProjectSave, FailureDuringTheWriteLeavesTheOldFileIntact)
{
    TemporaryFolder folder;
    saveProject(exampleProject(), folder / "p.ctproj");
    const std::string before = testing::readText(folder / "p.ctproj");
    Project edited = exampleProject();
    edited.name = "edited";
    AtomicWriteOptions failing;
    failing.hook = [](AtomicWriteStep step) {
        if (step == AtomicWriteStep::HalfWritten) throw std::runtime_error("disk full");
    };
    EXPECT_THROW(saveProject(edited, folder / "p.ctproj", {}, failing), std::runtime_error);
    EXPECT_EQ(testing::readText(folder / "p.ctproj"), before);
    EXPECT_EQ(loadProject(folder / "p.ctproj"), exampleProject());
}

TEST(ProjectLoad, MissingAndEmptyFilesAreFileErrors)
{
    TemporaryFolder folder;
    EXPECT_THROW(loadProject(folder / "none.ctproj"), FileError);
    testing::writeText(folder / "empty.ctproj", "");
    try {
        loadProject(folder / "empty.ctproj");
        FAIL();
    } catch (const FileError& error) {
        EXPECT_EQ(error.reason(), "file is empty");
    }
}

// "checks" (1.6): the project's clearance threshold, written only when set, read back exactly,
// refused when negative; a 1.5 file has none.
TEST(ProjectChecks, TheClearanceThresholdRoundTripsAndIsCheckedAtLoad)
{
    Project project = exampleProject();
    EXPECT_EQ(serialiseProject(project).find("\"checks\""), std::string::npos)
        << "not written when unset";
    project.checks.clearance = 0.0125;
    const std::string text = serialiseProject(project);
    const json written = json::parse(text);
    EXPECT_EQ(written["checks"]["clearance"], 0.0125);
    const Project reread = parseProject(text, "checks.ctproj");
    EXPECT_EQ(reread, project);
    EXPECT_EQ(serialiseProject(reread), text);

    json negative = written;
    negative["checks"]["clearance"] = -0.001;
    EXPECT_NE(loadError(negative).find("/checks/clearance"), std::string::npos)
        << loadError(negative);
    json unknown = written;
    unknown["checks"]["bend"] = 1.0;
    EXPECT_NE(loadError(unknown).find("/checks"), std::string::npos) << loadError(unknown);

    json older = exampleJson();
    older["version"] = "1.5";
    ProjectLoadReport report;
    EXPECT_FALSE(parseProject(older.dump(), "old.ctproj", {}, &report).checks.clearance);
    EXPECT_TRUE(report.migrated);
}

} // namespace
} // namespace chaintube::formats
