#include "test_util.h"

using namespace chaintube;
using namespace chaintube::test;

TEST(Scene, OnlyHosesWhoseInputsChangedAreRecomputed)
{
    Scene scene;
    for (int i = 0; i < 5; ++i)
        scene.addHose(Hose::straight(Vec3(0, 0, i), Vec3::UnitX(), 1.0, paperSpec()));
    EXPECT_EQ(scene.updateSurfaces().recomputed, 0) << "surfaces are built when hoses are added";
    static_cast<void>(scene.hose(2).grab(4, Vec3(0.3, 0.2, 2.0)));
    const auto before = scene.surface(1).positions();
    const std::vector<float> untouched(before.begin(), before.end());
    const Scene::FrameStats stats = scene.updateSurfaces();
    EXPECT_EQ(stats.recomputed, 1);
    EXPECT_EQ(stats.skipped, 4);
    const auto after = scene.surface(1).positions();
    EXPECT_EQ(std::vector<float>(after.begin(), after.end()), untouched);
    EXPECT_EQ(scene.updateSurfaces().recomputed, 0);
    // A rejected request changes nothing, so nothing is recomputed.
    EXPECT_EQ(scene.hose(3).grab(4, Vec3(NAN, 0, 0)).status, Status::InvalidInput);
    EXPECT_EQ(scene.updateSurfaces().recomputed, 0);
}
