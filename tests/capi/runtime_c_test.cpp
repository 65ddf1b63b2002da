// The C ABI from C++ (the header compiles as C++ too): the per-thread last error, rigs on two
// threads at once, and the load report's warnings. The figures themselves are compared with
// the C++ runtime by capi_replay_test (C) and CapiTest.exe (C#).
#include <chaintube/runtime_c.h>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

std::string readBytes(const std::string& file)
{
    std::ifstream stream(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

chaintube_rig* loadTestRig()
{
    chaintube_rig* rig = nullptr;
    EXPECT_EQ(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, CHAINTUBE_TEST_RIG, &rig),
              CHAINTUBE_OK)
        << chaintube_last_error();
    return rig;
}

TEST(RuntimeC, TheLastErrorIsPerThread)
{
    int32_t count = 0;
    ASSERT_EQ(chaintube_rig_hose_count(nullptr, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT);
    const std::string here = chaintube_last_error();
    EXPECT_EQ(here, "chaintube_rig_hose_count: rig is NULL: expected a valid pointer");
    std::string freshThread, otherThread;
    std::thread other([&] {
        freshThread = chaintube_last_error();
        int32_t node = 0;
        chaintube_rig_find_node(nullptr, "valve", &node);
        otherThread = chaintube_last_error();
    });
    other.join();
    EXPECT_EQ(freshThread, "");
    EXPECT_EQ(otherThread, "chaintube_rig_find_node: rig is NULL: expected a valid pointer");
    EXPECT_EQ(chaintube_last_error(), here);
}

TEST(RuntimeC, TwoRigsRunOnTwoThreadsAtOnceAndAgree)
{
    chaintube_rig* rigs[2] = {loadTestRig(), loadTestRig()};
    ASSERT_TRUE(rigs[0] && rigs[1]);
    std::vector<double> poses[2];
    const auto run = [&](int r) {
        chaintube_rig* rig = rigs[r];
        int32_t hose = -1, points[64];
        chaintube_hose_info info{};
        if (chaintube_rig_find_hose(rig, "right-return", &hose) != CHAINTUBE_OK ||
            chaintube_rig_hose_info(rig, hose, &info) != CHAINTUBE_OK ||
            chaintube_rig_grabbable_points(rig, hose, points, 64) != CHAINTUBE_OK)
            return;
        std::vector<double> world(7 * static_cast<size_t>(info.joint_count));
        const int32_t point = points[info.grabbable_count / 2];
        for (int frame = 0; frame < 50; ++frame) {
            if (chaintube_rig_joint_poses_f64(rig, hose, nullptr, 0, world.data(),
                                              static_cast<int32_t>(world.size())) != CHAINTUBE_OK)
                return;
            const double target[3] = {world[7 * point] + 0.0005, world[7 * point + 1],
                                      world[7 * point + 2] + 0.0002};
            if (chaintube_rig_grab(rig, hose, point, target, nullptr) != CHAINTUBE_OK ||
                chaintube_rig_update(rig, nullptr) != CHAINTUBE_OK)
                return;
        }
        poses[r] = world;
    };
    std::thread first(run, 0), second(run, 1);
    first.join();
    second.join();
    ASSERT_FALSE(poses[0].empty());
    EXPECT_EQ(poses[0], poses[1]);
    EXPECT_EQ(chaintube_rig_destroy(rigs[0]), CHAINTUBE_OK);
    EXPECT_EQ(chaintube_rig_destroy(rigs[1]), CHAINTUBE_OK);
}

TEST(RuntimeC, ReportsTheWarningOfADescriptorTakenFromTheSidecar)
{
    nlohmann::json gltf = nlohmann::json::parse(readBytes(CHAINTUBE_TEST_RIG_SPLIT ".gltf"));
    gltf.erase("extensions"); // what a tool that drops unknown extensions does
    const std::string stripped = gltf.dump();
    const std::string sidecar = readBytes(CHAINTUBE_TEST_RIG_SPLIT ".hoses.json");
    const std::string bin = readBytes(CHAINTUBE_TEST_RIG_SPLIT ".bin");
    const chaintube_bytes buffers[1] = {{bin.data(), bin.size()}};
    chaintube_rig* rig = nullptr;
    ASSERT_EQ(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "stripped.gltf",
                                        stripped.data(), stripped.size(), buffers, 1,
                                        sidecar.data(), sidecar.size(), &rig),
              CHAINTUBE_OK)
        << chaintube_last_error();
    int32_t count = -1;
    const char* text = nullptr;
    ASSERT_EQ(chaintube_rig_warning_count(rig, &count), CHAINTUBE_OK);
    ASSERT_EQ(count, 1);
    ASSERT_EQ(chaintube_rig_warning(rig, 0, &text), CHAINTUBE_OK);
    EXPECT_STREQ(text, "stripped.gltf: no CHAINTUBE_hose_rig extension; using the descriptor in "
                       "stripped.hoses.json");
    EXPECT_EQ(chaintube_rig_warning(rig, 1, &text), CHAINTUBE_ERROR_OUT_OF_RANGE);
    EXPECT_STREQ(chaintube_last_error(),
                 "chaintube_rig_warning: warning 1 is out of range: the rig has 1 warnings");
    int32_t hoses = 0;
    EXPECT_EQ(chaintube_rig_hose_count(rig, &hoses), CHAINTUBE_OK);
    EXPECT_EQ(hoses, 2);
    EXPECT_EQ(chaintube_rig_destroy(rig), CHAINTUBE_OK);
}

} // namespace
