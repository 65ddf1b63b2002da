// buildHoses(): project hoses become chaintube::Hose objects fixed to scene nodes.
#include "chaintube/formats/project_hoses.h"

#include <gtest/gtest.h>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;

TEST(BuildHoses, SingleHoseIsTheStraightTwelveSegmentHoseOfThePaper)
{
    const Project project = loadProject(kSamples / "single-hose.ctproj");
    const std::vector<Hose> hoses = buildHoses(project, {});
    ASSERT_EQ(hoses.size(), 1u);
    EXPECT_EQ(hoses[0].segmentCount(), 12);
    EXPECT_NEAR(hoses[0].restLengthTotal(), 0.6, 1e-9);
    EXPECT_TRUE(hoses[0].point(0).isApprox(Vec3(0, 0.5, 0)));
    EXPECT_TRUE(hoses[0].attachments().empty());
}

TEST(BuildHoses, TestRigHosesAreFixedToTheirSceneNodes)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    const Project project = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    const std::vector<Hose> hoses = buildHoses(project, scenes);
    ASSERT_EQ(hoses.size(), 2u);
    const ImportedScene& rig = scenes.at("rig");
    const Hose& left = hoses[0];
    ASSERT_EQ(left.attachments().size(), 2u);
    EXPECT_EQ(left.attachments()[0].first, 0);
    EXPECT_EQ(left.attachments()[0].last, 1);
    // The attachment frame is the node's world frame times the offset (0.1 m up the bracket).
    const Frame bracket = rig.worldFrame(rig.findNode("/test-rig/bracket_left"));
    EXPECT_TRUE(left.attachments()[0].frame.translation.isApprox(
        bracket.translation + Vec3(0, 0.1, 0), 1e-12));
    const Frame inlet = rig.worldFrame(rig.findNode("/test-rig/valve/valve_inlet"));
    EXPECT_TRUE(left.attachments()[1].frame.rotation.isApprox(inlet.rotation, 1e-12));
    EXPECT_TRUE(left.isFixed(16));
    EXPECT_FALSE(left.isFixed(8));

    // Moving the valve drags the fixed end along rigidly.
    Hose moved = left;
    Frame shifted = left.attachments()[1].frame;
    shifted.translation += Vec3(0, 0.05, 0);
    const UpdateResult result = moved.moveAttachment(left.attachments()[1].id, shifted);
    EXPECT_NE(result.status, Status::InvalidInput);
    EXPECT_TRUE(moved.point(16).isApprox(left.point(16) + Vec3(0, 0.05, 0), 1e-9));
}

TEST(BuildHoses, EngineSampleBuildsAllHosesOnTheRealScene)
{
    const fs::path scenesDir = CHAINTUBE_SCENES_DIR;
    if (!fs::exists(scenesDir / "2CylinderEngine.glb"))
        GTEST_SKIP() << "2CylinderEngine.glb absent from " << scenesDir;
    const NamedRoots roots{{"scenes", scenesDir}};
    for (const char* name : {"engine.ctproj", "engine-50-hoses.ctproj"}) {
        const fs::path file = kSamples / name;
        const Project project = loadProject(file, {roots});
        const ImportedScenes scenes = importProjectScenes(project, file, roots);
        const std::vector<Hose> hoses = buildHoses(project, scenes);
        ASSERT_EQ(hoses.size(), project.hoses.size());
        for (size_t i = 0; i < hoses.size(); ++i)
            EXPECT_EQ(hoses[i].attachments().size(), project.hoses[i].attachments.size()) << name;
    }
}

TEST(BuildHoses, UnknownNodeIsAnErrorNamingHoseAndNode)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    Project project = loadProject(file);
    project.hoses[0].attachments[0].node = "/test-rig/missing";
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    try {
        buildHoses(project, scenes);
        FAIL();
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what())
                      .find("hose 'left-feed': scene 'rig' has no node "
                            "'/test-rig/missing'"),
                  std::string::npos)
            << error.what();
    }
}

} // namespace
} // namespace chaintube::formats
