// HoseRuntime::loadFromMemory (what the C ABI and a browser load), release, frameResult and the
// unreadable-file error: the same rig as from the file, buffers and sidecar given in memory,
// and messages that name what the caller called the bytes.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>

namespace chaintube::exporting::testing {
namespace {

/// The world poses of every joint of every hose.
std::vector<Frame> allWorldPoses(const rig::HoseRuntime& runtime)
{
    std::vector<Frame> poses;
    for (int h = 0; h < runtime.hoseCount(); ++h)
        for (const rig::JointPose& pose : runtime.jointPoses(h))
            poses.push_back(pose.world);
    return poses;
}

void expectSamePoses(const std::vector<Frame>& a, const std::vector<Frame>& b)
{
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].translation, b[i].translation) << i;
        EXPECT_EQ(a[i].rotation.coeffs(), b[i].rotation.coeffs()) << i;
    }
}

/// Grabs the middle free point of the first grabbable hose 5 cm up, moves the first attachment
/// node 2 cm along x, and updates.
void runAFrame(rig::HoseRuntime& runtime)
{
    for (int h = 0; h < runtime.hoseCount(); ++h) {
        const std::vector<int>& free = runtime.description(h).grabbablePoints;
        if (free.empty()) continue;
        const int point = free[free.size() / 2];
        ASSERT_NE(runtime.grab(h, point, runtime.hose(h).point(point) + Vec3(0, 0.05, 0)).status,
                  Status::InvalidInput);
        break;
    }
    for (const rig::RigAttachment& attachment : runtime.description(0).attachments)
        if (attachment.node >= 0) {
            rig::NodeTransform moved = runtime.node(attachment.node).local;
            moved.translation.x() += 0.02;
            for (const rig::HoseUpdate& update : runtime.setNodeTransform(attachment.node, moved))
                ASSERT_NE(update.result.status, Status::InvalidInput);
            break;
        }
    runtime.update();
}

TEST(HoseRuntimeFromMemory, GivesTheSameRigAsTheFileAndKeepsNoReferenceToTheBytes)
{
    TemporaryFolder folder;
    for (const std::string sample : {"test-rig", "rig-options"}) {
        const fs::path output = folder / (sample + ".glb");
        exportProjectFile(projectFileOf(sample), output, roots());
        rig::HoseRuntime fromFile = rig::HoseRuntime::load(output);
        std::string bytes = readBytes(output);
        rig::ExportInMemory source;
        source.name = sample + ".glb";
        source.gltf = bytes;
        rig::RuntimeLoadReport report;
        rig::HoseRuntime fromMemory = rig::HoseRuntime::loadFromMemory(source, &report);
        std::fill(bytes.begin(), bytes.end(), '\0'); // the runtime copied what it needs
        EXPECT_EQ(report.descriptorSource, sample + ".glb#CHAINTUBE_hose_rig");
        EXPECT_EQ(fromMemory.hoseCount(), fromFile.hoseCount());
        EXPECT_EQ(fromMemory.nodeCount(), fromFile.nodeCount());
        EXPECT_EQ(fromMemory.colliders().size(), fromFile.colliders().size());
        expectSamePoses(allWorldPoses(fromMemory), allWorldPoses(fromFile));
        runAFrame(fromFile);
        runAFrame(fromMemory);
        expectSamePoses(allWorldPoses(fromMemory), allWorldPoses(fromFile));
    }
}

TEST(HoseRuntimeFromMemory, ReadsASplitGltfsBufferFromTheGivenBytesAndNamesAMissingOne)
{
    TemporaryFolder folder;
    const fs::path output = folder / "options.gltf";
    exportProjectFile(projectFileOf("rig-options"), output, roots());
    const std::string json = readBytes(output);
    const std::string bin = readBytes(folder / "options.bin");
    ASSERT_FALSE(bin.empty());
    rig::ExportInMemory source;
    source.name = "options.gltf";
    source.gltf = json;
    try { // the colliders' meshes are in buffer 0
        rig::HoseRuntime::loadFromMemory(source);
        FAIL() << "loaded collider meshes without their buffer";
    } catch (const Error& error) {
        EXPECT_NE(std::string(error.what())
                      .find("options.gltf: /buffers/0: the buffer \"options.bin\" "
                            "was not given"),
                  std::string::npos)
            << error.what();
    }
    source.buffers = {bin};
    const rig::HoseRuntime fromMemory = rig::HoseRuntime::loadFromMemory(source);
    const rig::HoseRuntime fromFile = rig::HoseRuntime::load(output);
    ASSERT_EQ(fromMemory.colliders().size(), 2u);
    expectSamePoses(allWorldPoses(fromMemory), allWorldPoses(fromFile));
}

TEST(HoseRuntimeFromMemory, UsesAGivenSidecarWhenTheExtensionWasStrippedAndNamesBoth)
{
    TemporaryFolder folder;
    const fs::path output = folder / "rig.gltf";
    exportProjectFile(samplesDir() / "test-rig.ctproj", output, roots());
    Json gltf = Json::parse(readBytes(output));
    gltf.erase("extensions");
    const std::string stripped = gltf.dump();
    const std::string sidecar = readBytes(folder / "rig.hoses.json");
    rig::ExportInMemory source;
    source.name = "downloaded/rig.gltf";
    source.gltf = stripped;
    try {
        rig::HoseRuntime::loadFromMemory(source);
        FAIL() << "loaded without any descriptor";
    } catch (const Error& error) {
        EXPECT_STREQ(error.what(),
                     "downloaded/rig.gltf: has no CHAINTUBE_hose_rig extension and no "
                     "sidecar descriptor was given");
    }
    source.sidecarDescriptor = sidecar;
    rig::RuntimeLoadReport report;
    const rig::HoseRuntime runtime = rig::HoseRuntime::loadFromMemory(source, &report);
    EXPECT_EQ(runtime.hoseCount(), 2);
    EXPECT_EQ(report.descriptorSource, "downloaded/rig.hoses.json");
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("downloaded/rig.hoses.json"), std::string::npos);
    // A malformed sidecar: the error names it and the JSON pointer.
    source.sidecarDescriptor = "{\"format\": 1}";
    try {
        rig::HoseRuntime::loadFromMemory(source);
        FAIL() << "loaded a malformed sidecar";
    } catch (const rig::DescriptorError& error) {
        EXPECT_EQ(error.source(), "downloaded/rig.hoses.json");
        EXPECT_EQ(error.pointer(), "/format");
    }
}

TEST(HoseRuntimeFromMemory, RejectsMalformedGlbBytesNamingTheGivenName)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "test-rig.ctproj", folder / "rig.glb", roots());
    const std::string glb = readBytes(folder / "rig.glb");
    const auto messageOf = [](std::string_view bytes) {
        rig::ExportInMemory source;
        source.name = "asset.glb";
        source.gltf = bytes;
        try {
            rig::HoseRuntime::loadFromMemory(source);
        } catch (const Error& error) {
            return std::string(error.what());
        }
        return std::string("loaded");
    };
    EXPECT_EQ(messageOf(std::string_view(glb).substr(0, 12)), "asset.glb: truncated GLB header");
    EXPECT_EQ(messageOf(std::string_view(glb).substr(0, glb.size() - 4)),
              "asset.glb: GLB header length does not match the file size");
    std::string version3 = glb;
    version3[4] = 3;
    EXPECT_EQ(messageOf(version3), "asset.glb: GLB container version 3, expected 2");
    EXPECT_EQ(messageOf("{\"nodes\": 5}").rfind("asset.glb: /nodes: ", 0), 0u);
    EXPECT_EQ(messageOf("").rfind("asset.glb: malformed glTF JSON", 0), 0u);
}

TEST(HoseRuntime, AnUnreadableFileIsAnUnreadableFileErrorNamingIt)
{
    try {
        rig::HoseRuntime::load("/nonexistent/folder/rig.glb");
        FAIL() << "loaded a missing file";
    } catch (const rig::UnreadableFile& error) {
        EXPECT_STREQ(error.what(),
                     "/nonexistent/folder/rig.glb: cannot be read (missing or no permission)");
    }
}

TEST(HoseRuntime, FrameResultCombinesTheCallsOfTheFrameTheLastUpdateClosed)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "test-rig.ctproj", folder / "rig.glb", roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "rig.glb");
    const int hose = runtime.findHose("left-feed");
    ASSERT_GE(hose, 0);
    const std::vector<int>& free = runtime.description(hose).grabbablePoints;
    const int point = free[free.size() / 2];
    const Vec3 start = runtime.hose(hose).point(point);

    // Out of reach first, then within: the frame keeps the worst, not the last.
    const UpdateResult clamped = runtime.grab(hose, point, start + Vec3(5, 0, 0));
    ASSERT_EQ(clamped.status, Status::Clamped);
    const UpdateResult reached = runtime.grab(hose, point, start + Vec3(0, 0.01, 0));
    ASSERT_EQ(reached.status, Status::Ok);
    EXPECT_EQ(runtime.grab(hose, 0, start).status, Status::InvalidInput); // refused: not counted
    // Before update() the frame is not closed: the previous (empty) frame is reported.
    EXPECT_EQ(runtime.frameResult(hose).status, Status::Ok);
    EXPECT_EQ(runtime.frameResult(hose).movedPoints, 0);
    runtime.update();
    const UpdateResult& frame = runtime.frameResult(hose);
    EXPECT_EQ(frame.status, Status::Clamped);
    EXPECT_EQ(frame.grabError, clamped.grabError);
    EXPECT_GT(frame.grabError, 1.0);
    EXPECT_EQ(frame.movedPoints, reached.movedPoints + clamped.movedPoints);
    const int other = 1 - hose;
    EXPECT_EQ(runtime.frameResult(other).movedPoints, 0) << "nothing touched the other hose";
    // A frame without input: all Ok and 0 again.
    runtime.update();
    EXPECT_EQ(runtime.frameResult(hose).status, Status::Ok);
    EXPECT_EQ(runtime.frameResult(hose).grabError, 0.0);
    EXPECT_EQ(runtime.frameResult(hose).movedPoints, 0);
}

TEST(HoseRuntime, ReleaseLetsAHeldGravityHoseFallAgain)
{
    TemporaryFolder folder;
    exportProjectFile(testDataDir() / "rig-options.ctproj", folder / "options.glb", roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "options.glb");
    const int tail = runtime.findHose("valve-tail");
    ASSERT_GE(tail, 0);
    const int middle = runtime.hose(tail).pointCount() / 2;
    ASSERT_NE(
        runtime.grab(tail, middle, runtime.hose(tail).point(middle) + Vec3(0.0, 0.03, 0.0)).status,
        Status::InvalidInput);
    const Vec3 held = runtime.hose(tail).point(middle); // where the grab put it
    for (int frame = 0; frame < 20; ++frame)
        runtime.update();
    EXPECT_LT((runtime.hose(tail).point(middle) - held).norm(), 1e-9) << "held while grabbed";
    EXPECT_FALSE(runtime.release(-1));
    EXPECT_FALSE(runtime.release(runtime.hoseCount()));
    EXPECT_TRUE(runtime.release(tail));
    for (int frame = 0; frame < 20; ++frame)
        runtime.update();
    EXPECT_LT(runtime.hose(tail).point(middle).y(), held.y() - 1e-3) << "falls once released";
}

} // namespace
} // namespace chaintube::exporting::testing
