// Sockets and plugs (format 1.7): couplings on parts with a capture zone and a tag, and the plug
// tags of a hose's ends. They round-trip exactly, a 1.6 file loads unchanged without them, and
// each bad value is refused naming the file, the JSON pointer and what was expected.
#include "chaintube/formats/project.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <numbers>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

Project projectWithSockets()
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    project.sockets.clear();
    Socket inlet;
    inlet.id = "inlet";
    inlet.scene = project.scenes.at(0).id;
    inlet.node = "/test-rig/valve";
    inlet.position = Vec3(0.01, 0.02, -0.03);
    inlet.axis = Vec3(0.0, 2.0, 0.0); // not unit: kept as written
    inlet.captureRadius = 0.025;
    inlet.captureAngle = 0.6;
    inlet.tag = "camlock-3/4";
    project.sockets.push_back(inlet);
    Socket spare = inlet;
    spare.id = "spare";
    spare.position = Vec3(0.2, 0.0, 0.0);
    spare.captureAngle = std::numbers::pi;
    project.sockets.push_back(spare);
    project.hoses.at(0).plugs = {"camlock-3/4", ""};
    return project;
}

/// The error parsing `document` (as "rig.ctproj") throws; fails the test if it is accepted.
ProjectFormatError loadError(const json& document)
{
    try {
        parseProject(document.dump(), "rig.ctproj");
    } catch (const ProjectFormatError& error) {
        return error;
    }
    ADD_FAILURE() << "accepted: " << document.dump();
    return ProjectFormatError("rig.ctproj", "", "accepted");
}

TEST(Sockets, RoundTripExactlyAndAreWrittenInTheNewestVersion)
{
    const Project project = projectWithSockets();
    const std::string text = serialiseProject(project);
    const json written = json::parse(text);
    EXPECT_EQ(written["version"], "1.7");
    ASSERT_EQ(written["sockets"].size(), 2u);
    EXPECT_EQ(written["sockets"][0]["tag"], "camlock-3/4");
    EXPECT_EQ(written["sockets"][0]["axis"], json::array({0.0, 2.0, 0.0}));
    EXPECT_EQ(written["hoses"][0]["plugs"], json({{"start", "camlock-3/4"}}));
    const Project reread = parseProject(text, "rig.ctproj");
    EXPECT_EQ(reread, project);
    EXPECT_EQ(serialiseProject(reread), text);
    ASSERT_NE(reread.findSocket("spare"), nullptr);
    EXPECT_EQ(reread.findSocket("spare")->captureAngle, std::numbers::pi);
    EXPECT_EQ(reread.findSocket("nothing"), nullptr);

    Project changed = project;
    changed.sockets[1].tag = "other";
    EXPECT_NE(changed, project);
    changed = project;
    changed.hoses[0].plugs.end = "camlock-3/4";
    EXPECT_NE(changed, project);
}

TEST(Sockets, SaveAndLoadThroughAFileKeepThem)
{
    const fs::path folder = fs::temp_directory_path() / "chaintube-sockets-test";
    fs::remove_all(folder);
    fs::create_directories(folder);
    Project project = projectWithSockets();
    const fs::path file = folder / "rig.ctproj";
    // The sample's scene path is relative to the samples folder: rebased, it names the same file.
    project = rebaseProject(project, kSamples / "test-rig.ctproj", file);
    saveProject(project, file);
    EXPECT_EQ(loadProject(file), project);
    fs::remove_all(folder);
}

TEST(Sockets, AProjectWithoutThemWritesNeitherKey)
{
    Project project = projectWithSockets();
    project.sockets.clear();
    project.hoses[0].plugs = {};
    const json written = json::parse(serialiseProject(project));
    EXPECT_FALSE(written.contains("sockets"));
    EXPECT_FALSE(written["hoses"][0].contains("plugs"));
}

TEST(Sockets, AVersion16FileLoadsUnchangedWithNoSockets)
{
    const std::string current = serialiseProject(loadProject(kSamples / "test-rig.ctproj"));
    json older = json::parse(current);
    older["version"] = "1.6";
    older.erase("sockets");
    for (json& hose : older["hoses"])
        hose.erase("plugs");
    ProjectLoadReport report;
    const Project project = parseProject(older.dump(), "older.ctproj", {}, &report);
    EXPECT_TRUE(report.migrated);
    EXPECT_EQ(report.fileVersion, "1.6");
    EXPECT_TRUE(report.ignoredKeys.empty());
    EXPECT_TRUE(project.sockets.empty());
    for (const HoseDefinition& hose : project.hoses)
        EXPECT_TRUE(hose.plugs.empty()) << hose.id;
    Project expected = loadProject(kSamples / "test-rig.ctproj");
    expected.sockets.clear();
    for (HoseDefinition& hose : expected.hoses)
        hose.plugs = {};
    EXPECT_EQ(project, expected);
    // Written back as 1.7: the same document but for the version.
    json rewritten = json::parse(serialiseProject(project));
    EXPECT_EQ(rewritten["version"], "1.7");
    rewritten["version"] = "1.6";
    EXPECT_EQ(rewritten, older);
}

TEST(Sockets, EachBadValueIsRefusedNamingFilePointerAndExpectation)
{
    const json good = json::parse(serialiseProject(projectWithSockets()));
    struct Case
    {
        const char* field;
        json value;
        const char* pointer;
        const char* expectation;
    };
    const Case cases[] = {
        {"captureRadius", 0.0, "/sockets/1/captureRadius", "expected a number in (0, inf)"},
        {"captureRadius", -0.01, "/sockets/1/captureRadius", "expected a number in (0, inf)"},
        {"captureRadius", "2 cm", "/sockets/1/captureRadius", "expected a number"},
        {"captureAngle", 0.0, "/sockets/1/captureAngle", "expected a number in (0, pi]"},
        {"captureAngle", 3.2, "/sockets/1/captureAngle", "expected a number in (0, pi]"},
        {"axis", json::array({0.0, 0.0, 0.0}), "/sockets/1/axis", "expected a non-zero direction"},
        {"axis", json::array({0.0, 1.0}), "/sockets/1/axis", "exactly 3 elements"},
        {"scene", "nowhere", "/sockets/1/scene", "expected the id of a scene of this project"},
        {"node", "part", "/sockets/1/node", "expected a node path starting with '/'"},
        {"id", "inlet", "/sockets/1/id", "\"inlet\" is used twice"},
        {"tag", "", "/sockets/1/tag", "expected a non-empty string"},
        {"extra", 1, "/sockets/1/extra", "unknown key \"extra\""},
    };
    for (const Case& item : cases) {
        json document = good;
        document["sockets"][1][item.field] = item.value;
        const ProjectFormatError error = loadError(document);
        EXPECT_EQ(error.jsonPointer(), item.pointer) << error.what();
        const std::string message = error.what();
        EXPECT_NE(message.find("rig.ctproj"), std::string::npos) << message;
        EXPECT_NE(message.find(item.expectation), std::string::npos) << message;
    }
    json missing = good;
    missing["sockets"][0].erase("tag");
    EXPECT_EQ(loadError(missing).jsonPointer(), "/sockets/0");

    json badPlug = good;
    badPlug["hoses"][0]["plugs"]["middle"] = "x";
    EXPECT_EQ(loadError(badPlug).jsonPointer(), "/hoses/0/plugs/middle");
    badPlug = good;
    badPlug["hoses"][0]["plugs"]["end"] = "";
    EXPECT_EQ(loadError(badPlug).jsonPointer(), "/hoses/0/plugs/end");
}

} // namespace
} // namespace chaintube::formats
