// Clips in the project (format 1.5, a hose's "clips"): saved per node path, read back exactly,
// absent from older files (which load unchanged), refused with precise errors when malformed;
// built where the hose is at the clip's place, on the node's frame, and carried by a pose
// override of the node like an attachment.
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "test_files.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

/// The test rig with a sliding clip on the floor plate halfway along the left hose and a
/// sliding-turning one with end stops on the right hose.
Project rigWithClips()
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    HoseClip half;
    half.scene = "rig";
    half.node = "/test-rig/floor_plate";
    half.place = 0.5 * *project.hoses[0].length;
    project.hoses[0].clips.push_back(half);
    HoseClip stops;
    stops.scene = "rig";
    stops.node = "/test-rig/bracket_right";
    stops.offset.translation = Vec3(0.0, 0.01, 0.0);
    stops.place = 0.2;
    stops.hold = Hold::SlidingTurning;
    stops.slideMin = 0.1;
    stops.slideMax = 0.3;
    project.hoses[1].clips.push_back(stops);
    return project;
}

std::string clipError(const json& document)
{
    try {
        parseProject(document.dump(), "clipped.ctproj");
    } catch (const ProjectFormatError& error) {
        return error.what();
    }
    ADD_FAILURE() << "accepted: " << document.dump();
    return {};
}

TEST(Clips, ClipsRoundTripExactly)
{
    testing::TemporaryFolder folder;
    const Project project = rigWithClips();
    fs::create_directories(folder / "scenes");
    fs::copy_file(kSamples / "scenes" / "test-rig.gltf", folder / "scenes" / "test-rig.gltf");
    saveProject(project, folder / "clipped.ctproj");
    const json written = json::parse(testing::readText(folder / "clipped.ctproj"));
    EXPECT_EQ(written["version"], "1.7");
    const json& first = written["hoses"][0]["clips"][0];
    EXPECT_EQ(first["node"], "/test-rig/floor_plate");
    EXPECT_EQ(first["hold"], "sliding");
    EXPECT_FALSE(first.contains("slideMin")) << "no end stop: not written";
    const json& second = written["hoses"][1]["clips"][0];
    EXPECT_EQ(second["hold"], "sliding-turning");
    EXPECT_EQ(second["slideMin"], 0.1);
    EXPECT_EQ(second["slideMax"], 0.3);
    EXPECT_EQ(second["offset"]["translation"], json::array({0.0, 0.01, 0.0}));
    const Project loaded = loadProject(folder / "clipped.ctproj");
    EXPECT_EQ(loaded, project);
    EXPECT_EQ(serialiseProject(loaded), testing::readText(folder / "clipped.ctproj"));
    // Every field takes part in equality.
    const auto changed = [&](auto edit) {
        Project copy = project;
        edit(copy.hoses[1].clips[0]);
        return copy != project;
    };
    EXPECT_TRUE(changed([](HoseClip& c) { c.node = "/test-rig"; }));
    EXPECT_TRUE(changed([](HoseClip& c) { c.place += 1e-12; }));
    EXPECT_TRUE(changed([](HoseClip& c) { c.hold = Hold::Sliding; }));
    EXPECT_TRUE(changed([](HoseClip& c) { c.slideMin.reset(); }));
    EXPECT_TRUE(changed([](HoseClip& c) { c.slideMax = 0.31; }));
    EXPECT_TRUE(changed([](HoseClip& c) { c.offset.translation.x() = 1e-9; }));
}

TEST(Clips, AFileBefore1_5LoadsUnchangedWithNoClips)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    json document = json::parse(testing::readText(file));
    document["version"] = "1.4";
    ProjectLoadReport report;
    const Project old = parseProject(document.dump(), file, {}, &report);
    EXPECT_EQ(report.fileVersion, "1.4");
    for (const HoseDefinition& hose : old.hoses)
        EXPECT_TRUE(hose.clips.empty());
    EXPECT_EQ(old, loadProject(file));
    EXPECT_FALSE(json::parse(serialiseProject(old))["hoses"][0].contains("clips"))
        << "a hose without clips is written without the key";
}

TEST(Clips, BadClipsAreRefusedNamingFileFieldAndExpectation)
{
    const json base = json::parse(serialiseProject(rigWithClips()));
    const auto with = [&](auto edit) {
        json document = base;
        edit(document["hoses"][1]["clips"][0]);
        return clipError(document);
    };
    EXPECT_EQ(with([](json& c) { c["hold"] = "fixed"; }),
              "clipped.ctproj: /hoses/1/clips/0/hold: expected \"sliding\" or "
              "\"sliding-turning\", got \"fixed\"");
    EXPECT_EQ(with([](json& c) { c["place"] = -0.1; }),
              "clipped.ctproj: /hoses/1/clips/0/place: expected a number in [0, inf), got -0.1");
    EXPECT_EQ(with([](json& c) { c["slideMin"] = 0.25; }),
              "clipped.ctproj: /hoses/1/clips/0/slideMin: expected a number in [0, 0.2], got "
              "0.25");
    EXPECT_EQ(with([](json& c) { c["slideMax"] = 0.15; }),
              "clipped.ctproj: /hoses/1/clips/0/slideMax: expected a number in [0.2, inf), got "
              "0.15");
    EXPECT_EQ(with([](json& c) { c["scene"] = "elsewhere"; }),
              "clipped.ctproj: /hoses/1/clips/0/scene: expected the id of a scene of this "
              "project, got \"elsewhere\"");
    EXPECT_EQ(with([](json& c) { c["node"] = "plate"; }),
              "clipped.ctproj: /hoses/1/clips/0/node: expected a node path starting with '/', "
              "got \"plate\"");
    EXPECT_EQ(with([](json& c) { c.erase("place"); }),
              "clipped.ctproj: /hoses/1/clips/0: missing required key \"place\"");
    EXPECT_EQ(with([](json& c) {
                  c["points"] = json::array({1, 2});
              }),
              "clipped.ctproj: /hoses/1/clips/0/points: unknown key \"points\" (expected one of: "
              "scene, node, offset, place, hold, slideMin, slideMax)");
}

TEST(Clips, AClipIsBuiltWhereTheHoseIsAtItsPlaceAndFollowsAPosedNode)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    Project project = rigWithClips();
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    const Hose plain = buildHose(project, loadProject(file).hoses[0], scenes);
    const Hose hose = buildHose(project, project.hoses[0], scenes);
    ASSERT_EQ(hose.attachments().size(), 3u) << "two attachments, then the clip";
    const Hose::Attachment& clip = hose.attachments()[2];
    EXPECT_EQ(clip.hold, Hold::Sliding);
    EXPECT_EQ(plain.points(), hose.points()) << "adding the clip moves nothing";
    // Its centre is the point at half the rest length: on segment 7 or 8 of 16, on the axis.
    const double half = 0.5 * *project.hoses[0].length;
    EXPECT_DOUBLE_EQ(clip.slide, half);
    const Vec3 centre = clip.frame.apply(clip.clipCentre);
    const Vec3 a = hose.point(clip.first), b = hose.point(clip.last);
    EXPECT_NEAR(
        ((centre - a) - (centre - a).dot((b - a).normalized()) * (b - a).normalized()).norm(), 0.0,
        1e-12);
    EXPECT_NEAR(hose.attachmentGap(clip.id), 0.0, 1e-12);
    // The clip's part lifted 2 cm by a pose: the clip goes with it and the hose follows.
    NodePose lifted;
    lifted.scene = "rig";
    lifted.node = "/test-rig/floor_plate";
    const ImportedScene& rig = scenes.at("rig");
    lifted.localTransform =
        rig.nodes[static_cast<size_t>(rig.findNode(lifted.node))].localTransform;
    lifted.localTransform(1, 3) += 0.02;
    project.poses.push_back(lifted);
    UpdateResult update;
    const Hose posed = buildHose(project, project.hoses[0], scenes, &update);
    EXPECT_EQ(update.status, Status::Ok);
    const Hose::Attachment& carried = posed.attachments()[2];
    EXPECT_NEAR((carried.frame.apply(carried.clipCentre) - (centre + Vec3(0, 0.02, 0))).norm(), 0.0,
                1e-12);
    EXPECT_NEAR(posed.attachmentGap(carried.id), 0.0, 1e-9);
    EXPECT_TRUE(posed.measureViolation().ok());
    // A place beyond the hose's length is refused naming the hose and the clip.
    project.hoses[0].clips[0].place = 2.0;
    try {
        (void)buildHose(project, project.hoses[0], scenes);
        ADD_FAILURE() << "built";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("hose 'left-feed': clip 0: clip place"),
                  std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace chaintube::formats
