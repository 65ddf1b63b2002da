// Project format 1.2: per-hose gravity and torsion, collider nodes. Saved and read back exactly
// (load → save byte for byte), migrated from 1.1 (off, none), refused with the file, the JSON
// pointer and what was expected when malformed, and carried into the built hoses' HoseSpec.
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "test_files.h"

#include <cstdio>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

Project rigWithOptions()
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    project.hoses[0].gravity = {true, Vec3(0.0, -9.81, 0.5)};
    project.hoses[1].torsion = {true, 0.2};
    project.colliders = {{"rig", "/test-rig/floor_plate"}, {"rig", "/test-rig/valve"}};
    return project;
}

/// The pointer of the ProjectFormatError parsing `document` gives ("(parsed)" if none).
std::string pointerOfError(const json& document)
{
    try {
        parseProject(document.dump(2), kSamples / "options.ctproj");
    } catch (const ProjectFormatError& error) {
        EXPECT_NE(std::string(error.what()).find("options.ctproj"), std::string::npos)
            << error.what();
        return error.jsonPointer();
    }
    return "(parsed)";
}

TEST(HoseOptions, SaveThenLoadIsExactAndLoadThenSaveIsByteForByte)
{
    testing::TemporaryFolder folder;
    fs::copy(kSamples / "scenes", folder / "scenes", fs::copy_options::recursive);
    const Project project = rigWithOptions();
    const fs::path copy = folder / "options.ctproj";
    saveProject(project, copy);
    const std::string text = testing::readText(copy);
    ProjectLoadReport report;
    const Project reread = loadProject(copy, {}, &report);
    EXPECT_EQ(reread, project);
    EXPECT_FALSE(report.migrated);
    EXPECT_TRUE(reread.hoses[0].gravity.enabled);
    EXPECT_EQ(reread.hoses[0].gravity.direction, Vec3(0.0, -9.81, 0.5));
    EXPECT_FALSE(reread.hoses[0].torsion.enabled);
    EXPECT_EQ(reread.hoses[1].torsion.twistLimit, 0.2);
    ASSERT_EQ(reread.colliders.size(), 2u);
    EXPECT_EQ(reread.colliders[1].node, "/test-rig/valve");
    EXPECT_EQ(serialiseProject(reread), text) << "load → save must give the same bytes";
    // Unused options are not written: hose 1 has no "gravity", hose 0 no "torsion".
    const json saved = json::parse(text);
    EXPECT_FALSE(saved["hoses"][1].contains("gravity"));
    EXPECT_FALSE(saved["hoses"][0].contains("torsion"));
    // An option switched off keeps its authored parameter.
    Project off = project;
    off.hoses[0].gravity.enabled = false;
    EXPECT_EQ(parseProject(serialiseProject(off), copy), off);
}

TEST(HoseOptions, Version1_1FilesHaveTheOptionsOffAndNoCollidersAndAreMigrated)
{
    json document = json::parse(testing::readText(kSamples / "test-rig.ctproj"));
    document["version"] = "1.1";
    document.erase("colliders");
    ProjectLoadReport report;
    const Project project = parseProject(document.dump(2), kSamples / "old.ctproj", {}, &report);
    EXPECT_TRUE(report.migrated);
    for (const HoseDefinition& hose : project.hoses) {
        EXPECT_FALSE(hose.gravity.enabled);
        EXPECT_FALSE(hose.torsion.enabled);
    }
    EXPECT_TRUE(project.colliders.empty());
}

TEST(HoseOptions, MalformedOptionsNameThePointerAndTheExpectation)
{
    const json good = json::parse(serialiseProject(rigWithOptions()));
    EXPECT_EQ(pointerOfError(good), "(parsed)");

    json bad = good;
    bad["hoses"][0]["gravity"]["direction"] = json::array({0.0, 0.0, 0.0});
    EXPECT_EQ(pointerOfError(bad), "/hoses/0/gravity/direction");
    bad = good;
    bad["hoses"][0]["gravity"]["direction"] = json::array({0.0, "down", 0.0});
    EXPECT_EQ(pointerOfError(bad), "/hoses/0/gravity/direction/1");
    bad = good;
    bad["hoses"][0]["gravity"]["enabled"] = "yes";
    EXPECT_EQ(pointerOfError(bad), "/hoses/0/gravity/enabled");
    bad = good;
    bad["hoses"][0]["gravity"]["g"] = 9.81;
    EXPECT_EQ(pointerOfError(bad), "/hoses/0/gravity/g");
    bad = good;
    bad["hoses"][1]["torsion"]["twistLimit"] = 0.0;
    EXPECT_EQ(pointerOfError(bad), "/hoses/1/torsion/twistLimit");
    bad = good;
    bad["hoses"][1]["torsion"]["twistLimit"] = 3.5;
    EXPECT_EQ(pointerOfError(bad), "/hoses/1/torsion/twistLimit");
    bad = good;
    bad["hoses"][1]["torsion"].erase("enabled");
    EXPECT_EQ(pointerOfError(bad), "/hoses/1/torsion"); // a missing key: its object's pointer
    bad = good;
    bad["colliders"][0]["scene"] = "nope";
    EXPECT_EQ(pointerOfError(bad), "/colliders/0/scene");
    bad = good;
    bad["colliders"][1]["node"] = "test-rig/valve";
    EXPECT_EQ(pointerOfError(bad), "/colliders/1/node");
    bad = good;
    bad["colliders"][1] = bad["colliders"][0];
    EXPECT_EQ(pointerOfError(bad), "/colliders/1/node");
    bad = good;
    bad["colliders"] = json::object();
    EXPECT_EQ(pointerOfError(bad), "/colliders");
}

TEST(HoseOptions, BuiltHosesCarryGravityAndTorsionInTheirSpec)
{
    const Project project = rigWithOptions();
    const ImportedScenes scenes = importProjectScenes(project, kSamples / "test-rig.ctproj", {});
    const std::vector<Hose> hoses = buildHoses(project, scenes);
    ASSERT_EQ(hoses.size(), 2u);
    EXPECT_TRUE(hoses[0].spec().gravity.enabled);
    EXPECT_EQ(hoses[0].spec().gravity.direction, Vec3(0.0, -9.81, 0.5));
    EXPECT_FALSE(hoses[0].spec().torsion.enabled);
    EXPECT_TRUE(hoses[1].spec().torsion.enabled);
    EXPECT_EQ(hoses[1].spec().torsion.twistLimit, 0.2);
}

} // namespace
} // namespace chaintube::formats

namespace chaintube::formats {
namespace {
// Gravity on both hoses of the test rig as built from the project (clamped at parts, bend
// limited): every step keeps every constraint and moves no point by half a segment (a step
// that fell back on the exact pass from the fixed side made both hoses jump by several
// segments; see 350fa12).
TEST(HoseOptions, GravityOnTheTestRigsHosesNeverJumps)
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    for (HoseDefinition& hose : project.hoses)
        hose.gravity = {true, Vec3(0.0, -1.0, 0.0)};
    const ImportedScenes scenes =
        posedScenes(project, importProjectScenes(project, kSamples / "test-rig.ctproj", {}));
    std::vector<Hose> hoses = buildHoses(project, scenes);
    ASSERT_EQ(hoses.size(), 2u);
    for (Hose& hose : hoses) {
        const double segment = hose.restLengthTotal() / (hose.pointCount() - 1);
        double worstJump = 0.0;
        int steps = 0;
        for (; steps < 400; ++steps) {
            const std::vector<Vec3> before = hose.points();
            const std::uint64_t revision = hose.revision();
            const UpdateResult result = hose.step();
            EXPECT_EQ(result.status, Status::Ok);
            for (int i = 0; i < hose.pointCount(); ++i)
                worstJump =
                    std::max(worstJump, (hose.point(i) - before[static_cast<size_t>(i)]).norm());
            if (hose.revision() == revision) break;
        }
        std::printf(
            "[ figures ] %d points: settled after %d steps, largest move of a point in a step %.3f "
            "segments\n",
            hose.pointCount(), steps, worstJump / segment);
        EXPECT_LT(steps, 400);
        EXPECT_LT(worstJump, 0.5 * segment);
    }
}
} // namespace
} // namespace chaintube::formats
