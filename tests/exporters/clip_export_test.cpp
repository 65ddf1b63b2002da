// Clips through the whole chain: a project's clip is exported into the descriptor (1.4, "clips"),
// read back by the runtime, which adds it to the rebuilt hose; moving the clip's node carries the
// clip and the hose slides through it. A descriptor clip that the library could not add is
// refused naming the field.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <chaintube/formats/project_hoses.h>

namespace chaintube::exporting::testing {
namespace {

/// The test rig with a sliding clip on the floor plate halfway along left-feed.
formats::Project rigWithAClip(const fs::path& file)
{
    formats::Project project = loadWithRoots(file);
    formats::HoseClip clip;
    clip.scene = "rig";
    clip.node = "/test-rig/floor_plate";
    clip.place = 0.5 * *project.hoses[0].length;
    project.hoses[0].clips.push_back(clip);
    return project;
}

/// Distance of the clip's centre from the hose's axis.
double offAxis(const Hose& hose, const Hose::Attachment& clip)
{
    const Vec3 centre = clip.frame.apply(clip.clipCentre);
    const Vec3 a = hose.point(clip.first), d = (hose.point(clip.last) - a).normalized();
    return ((centre - a) - (centre - a).dot(d) * d).norm();
}

TEST(ClipExport, AClipTravelsFromTheProjectThroughTheDescriptorToTheRuntime)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    const formats::Project project = rigWithAClip(file);
    exportProject(project, file, folder / "clip.glb", roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "clip.glb");
    EXPECT_EQ(runtime.descriptor().version, "1.5");
    const int h = runtime.findHose("left-feed");
    ASSERT_GE(h, 0);
    const rig::RigHose& described = runtime.descriptor().hoses[static_cast<size_t>(h)];
    ASSERT_EQ(described.clips.size(), 1u);
    const rig::RigClip& clip = described.clips[0];
    EXPECT_EQ(clip.node, runtime.findNode("floor_plate"));
    EXPECT_NEAR(clip.place, project.hoses[0].clips[0].place, 1e-12);
    EXPECT_EQ(clip.hold, Hold::Sliding);
    EXPECT_EQ(runtime.findHose("right-return") >= 0 &&
                  runtime.descriptor()
                      .hoses[static_cast<size_t>(runtime.findHose("right-return"))]
                      .clips.empty(),
              true);
    // The runtime's hose holds it: two attachments, then the clip, met and on the axis.
    const Hose& hose = runtime.hose(h);
    ASSERT_EQ(hose.attachments().size(), 3u);
    const Hose::Attachment& held = hose.attachments()[2];
    EXPECT_TRUE(held.isClip());
    EXPECT_NEAR(hose.attachmentGap(held.id), 0.0, 1e-9);
    EXPECT_LE(offAxis(hose, held), 1e-9);
    const Vec3 centre = held.frame.apply(held.clipCentre);

    // The floor plate lifted 1.5 cm: the clip goes with it, the hose follows through it.
    const int plate = runtime.findNode("floor_plate");
    rig::NodeTransform local = runtime.node(plate).local;
    local.translation += Vec3(0.0, 0.015, 0.0);
    const std::vector<rig::HoseUpdate> updates = runtime.setNodeTransform(plate, local);
    ASSERT_EQ(updates.size(), 1u) << "only left-feed has something on the plate";
    EXPECT_EQ(updates[0].hose, h);
    EXPECT_EQ(updates[0].result.status, Status::Ok);
    const Hose& moved = runtime.hose(h);
    const Hose::Attachment& carried = moved.attachments()[2];
    EXPECT_NEAR((carried.frame.apply(carried.clipCentre) - (centre + Vec3(0, 0.015, 0))).norm(),
                0.0, 1e-9);
    EXPECT_NEAR(moved.attachmentGap(carried.id), 0.0, 1e-9);
    EXPECT_LE(offAxis(moved, carried), 1e-9);
    EXPECT_TRUE(moved.measureViolation().ok());
    EXPECT_NEAR(moved.currentLength(), hose.currentLength(), 1e-6 * hose.currentLength());
}

TEST(ClipExport, AClipDoesNotFixTheHoseToItsNodeSoAHoseFixedToOneNodeKeepsItsJointsThere)
{
    // samples/motion-rig.ctproj: carriage-cable is clamped on the base plate (points 0 and 1)
    // and runs through a clip on the carriage and a guide (a clip) on the base plate. Fixed to
    // one node, it hangs all its joints under its own joints node below the base plate (one
    // armature in Blender); the clips' points are free joints that slide at run time, and the
    // hose is not static.
    TemporaryFolder folder;
    const ExportReport report =
        exportProjectFile(samplesDir() / "motion-rig.ctproj", folder / "out.glb", roots());
    const GltfDocument exported = readGltf(folder / "out.glb");
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "out.glb");
    const int h = runtime.findHose("carriage-cable");
    ASSERT_GE(h, 0);
    const rig::RigHose& cable = report.descriptor.hoses[static_cast<size_t>(h)];
    EXPECT_FALSE(cable.isStatic);
    ASSERT_EQ(cable.attachments.size(), 1u);
    ASSERT_EQ(cable.clips.size(), 2u);
    EXPECT_EQ(runtime.node(cable.attachments[0].node).name, "base_plate");
    EXPECT_EQ(runtime.node(cable.clips[0].node).name, "carriage");
    EXPECT_EQ(runtime.node(cable.clips[1].node).name, "base_plate");
    EXPECT_EQ(runtime.node(cable.rigNode).parent, cable.attachments[0].node);
    ASSERT_EQ(cable.jointNodes.size(), 25u);
    for (const int joint : cable.jointNodes)
        EXPECT_EQ(runtime.node(joint).parent, cable.rigNode) << "joint node " << joint;
    // Each clip holds the segment at its place (0.3 m and 0.55 m, points 12's and 22's within
    // rounding). Its two points are grabbable points (the clip slides: which points it holds
    // changes, and the runtime refuses a grab only while it holds one); the clamp's two are not.
    std::vector<int> clipHeld;
    for (size_t k = 1; k < 3; ++k) {
        const Hose::Attachment& clip = runtime.hose(h).attachments().at(k);
        ASSERT_TRUE(clip.isClip());
        EXPECT_NEAR(clip.slide, cable.clips[k - 1].place, 1e-12);
        clipHeld.insert(clipHeld.end(), {clip.first, clip.last});
    }
    const auto listed = [&](int point) {
        return std::count(cable.grabbablePoints.begin(), cable.grabbablePoints.end(), point);
    };
    for (const int point : clipHeld) {
        EXPECT_EQ(listed(point), 1) << point;
        EXPECT_EQ(runtime.grab(h, point, runtime.hose(h).point(point)).status, Status::InvalidInput)
            << "point " << point << " is held by a clip now";
    }
    EXPECT_EQ(listed(0) + listed(1), 0);          // the clamp's
    EXPECT_EQ(cable.grabbablePoints.size(), 23u); // 25 points, 2 clamped
    EXPECT_EQ(exported.json["nodes"][static_cast<size_t>(cable.meshNode)].contains("skin"), true);
}

TEST(ClipExport, ADescriptorClipTheLibraryCouldNotAddIsRefusedNamingTheField)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    exportProject(rigWithAClip(file), file, folder / "clip.glb", roots());
    const std::string text = test_support::readText(folder / "clip.hoses.json");
    const Json base = Json::parse(text);
    ASSERT_EQ(base["hoses"][0]["clips"].size(), 1u);
    const auto refusal = [&](auto edit) {
        Json document = base;
        edit(document["hoses"][0]["clips"][0]);
        try {
            (void)rig::parseDescriptor(document.dump(), "clip.hoses.json");
        } catch (const rig::DescriptorError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_EQ(refusal([](Json& c) { c["place"] = 0.0; }),
              "clip.hoses.json: /hoses/0/clips/0/place: the segment holding the clip has point 0 "
              "fixed by an attachment or an earlier clip");
    EXPECT_NE(refusal([](Json& c) {
                  c["place"] = 5.0;
              }).find("/hoses/0/clips/0/place: expected a number in"),
              std::string::npos);
    EXPECT_NE(refusal([](Json& c) { c["hold"] = "fixed"; }).find("/hoses/0/clips/0/hold"),
              std::string::npos);
    EXPECT_NE(refusal([](Json& c) { c["slideMax"] = 0.01; }).find("/hoses/0/clips/0/"),
              std::string::npos);
    EXPECT_NE(refusal([](Json& c) { c["extra"] = 1; }).find("/hoses/0/clips/0/extra"),
              std::string::npos);
    // Unchanged, it parses and rebuilds.
    EXPECT_EQ(rig::rebuildHose(rig::parseDescriptor(text, "clip.hoses.json").hoses[0])
                  .attachments()
                  .size(),
              3u);
}

} // namespace
} // namespace chaintube::exporting::testing
