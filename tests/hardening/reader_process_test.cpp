// The child-process runner behind importScene (formats/src/reader_process.cpp, internal): a
// reader that crashes, exits, throws, stays silent or hands over a scene, driven directly so
// that every way a third-party reader can end is covered, not only the ones assimp happens to
// reach today.
#include "import_internal.h"

#include <chrono>
#include <csignal>
#include <gtest/gtest.h>
#include <thread>
#include <unistd.h>

namespace chaintube::formats::detail {
namespace {

const std::filesystem::path kFile = "/nonexistent/scene.ply"; // only named in messages

ReaderResult runReader(const std::function<ReaderResult(const ImportOptions&, ProgressStage&)>& reader,
                       const ImportOptions& options = {})
{
    ProgressStage stage(options, kFile, 0.0, 1.0);
    return readInChildProcess(kFile, "test reader", options, stage, reader);
}

TEST(ReaderProcess, AReaderKilledByASignalIsAnImportErrorNamingFileReaderAndSignal)
{
    try {
        runReader([](const ImportOptions&, ProgressStage&) -> ReaderResult {
            std::fputs("about to crash\n", stderr);
            std::raise(SIGSEGV);
            return {};
        });
        FAIL() << "no error";
    } catch (const ImportError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "/nonexistent/scene.ply: the test reader crashed on malformed data (signal " +
                      std::to_string(SIGSEGV) +
                      ", SIGSEGV: Segmentation fault); it wrote: about to crash");
        EXPECT_EQ(error.signal(), SIGSEGV);
        EXPECT_EQ(error.readerOutput(), "about to crash\n");
    }
}

TEST(ReaderProcess, AReaderThatExitsWithoutAnAnswerIsAnImportErrorWithItsExitStatus)
{
    try {
        runReader([](const ImportOptions&, ProgressStage&) -> ReaderResult { ::_exit(3); });
        FAIL() << "no error";
    } catch (const ImportError& error) {
        EXPECT_EQ(error.reason(), "the test reader ended without an answer (exit status 3)");
        EXPECT_EQ(error.signal(), 0);
        EXPECT_EQ(error.exitStatus(), 3);
    }
}

TEST(ReaderProcess, AFileErrorOfTheReaderComesBackWithItsReason)
{
    try {
        runReader([](const ImportOptions&, ProgressStage&) -> ReaderResult {
            throw FileError(kFile, "cannot read PLY file: no faces");
        });
        FAIL() << "no error";
    } catch (const ImportError& error) {
        FAIL() << "an ImportError: " << error.what();
    } catch (const FileError& error) {
        EXPECT_EQ(std::string(error.what()), "/nonexistent/scene.ply: cannot read PLY file: no faces");
    }
}

TEST(ReaderProcess, TheSceneComesBackEqual)
{
    ReaderResult sent;
    sent.metresPerReaderUnit = 0.001;
    sent.sourceUnitsPerReaderUnit = 2.0;
    sent.scene.format = "PLY";
    sent.scene.sourceUnits = {0.001, "millimetre", UnitSource::FileHeader, UpAxis::PositiveZ,
                              UnitSource::FormatConvention};
    SceneMesh mesh;
    mesh.name = "tri";
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    mesh.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    mesh.indices = {0, 1, 2};
    sent.scene.meshes = {mesh};
    SceneNode root, child;
    root.name = "root";
    root.children = {1};
    child.name = "part";
    child.parent = 0;
    child.meshes = {0};
    child.localTransform(0, 3) = 0.25;
    sent.scene.nodes = {root, child};
    const ReaderResult got = runReader([&](const ImportOptions&, ProgressStage&) { return sent; });
    EXPECT_EQ(got.metresPerReaderUnit, 0.001);
    EXPECT_EQ(got.sourceUnitsPerReaderUnit, 2.0);
    EXPECT_EQ(got.scene.format, "PLY");
    EXPECT_EQ(got.scene.sourceUnits.unitName, "millimetre");
    EXPECT_EQ(got.scene.sourceUnits.upAxis, UpAxis::PositiveZ);
    EXPECT_EQ(got.scene.sourceUnits.upAxisSource, UnitSource::FormatConvention);
    ASSERT_EQ(got.scene.meshes.size(), 1u);
    EXPECT_EQ(got.scene.meshes[0].name, "tri");
    EXPECT_EQ(got.scene.meshes[0].positions, mesh.positions);
    EXPECT_EQ(got.scene.meshes[0].normals, mesh.normals);
    EXPECT_EQ(got.scene.meshes[0].indices, mesh.indices);
    ASSERT_EQ(got.scene.nodes.size(), 2u);
    EXPECT_EQ(got.scene.nodes[1].name, "part");
    EXPECT_EQ(got.scene.nodes[1].parent, 0);
    EXPECT_EQ(got.scene.nodes[1].meshes, std::vector<int>{0});
    EXPECT_EQ(got.scene.nodes[1].localTransform, child.localTransform);
    EXPECT_EQ(got.scene.nodes[0].children, std::vector<int>{1});
}

TEST(ReaderProcess, ProgressIsForwardedAndACancelKillsASilentReader)
{
    // The reader reports once, then stays silent for a minute (as assimp does inside one step):
    // the callback is asked again while it is silent, and its "stop" ends the child.
    std::vector<double> reports;
    ImportOptions options;
    options.progress = [&](double fraction) {
        reports.push_back(fraction);
        return reports.size() < 3;
    };
    const auto start = std::chrono::steady_clock::now();
    EXPECT_THROW(runReader(
                     [](const ImportOptions&, ProgressStage& progress) -> ReaderResult {
                         progress.report(0.25);
                         std::this_thread::sleep_for(std::chrono::seconds(60));
                         return {};
                     },
                     options),
                 Cancelled);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_GE(reports.size(), 3u);
    EXPECT_EQ(reports[0], 0.25);
    EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
    // Not a timing assertion on the machine's speed: the reader alone would take 60 s.
    EXPECT_LT(seconds, 30.0) << "the cancel waited for the silent reader";
}

} // namespace
} // namespace chaintube::formats::detail
