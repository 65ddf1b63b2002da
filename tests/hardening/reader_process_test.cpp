// The child-process runner behind importScene (formats/src/reader_process.cpp, internal): a
// reader that crashes, exits, throws, stays silent or hands over a scene, driven directly so
// that every way a third-party reader can end is covered, not only the ones assimp happens to
// reach today.
#include "test_reader_scene.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <fstream>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <utility>

namespace chaintube::formats::detail {
namespace {

const std::filesystem::path kFile = "/nonexistent/scene.ply"; // only named in messages

/// Runs chaintube-test-reader, which ends as `how` says (test_reader_main.cpp).
ReaderResult runReader(const std::string& how, const ImportOptions& options = {})
{
    ProgressStage stage(options, kFile, 0.0, 1.0);
    return readInChildProcess(kFile, "test reader", options, stage, {CHAINTUBE_TEST_READER, {how}});
}
TEST(ReaderProcess, AReaderKilledByASignalIsAnImportErrorNamingFileReaderAndSignal)
{
    try {
        runReader("crash");
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
        runReader("exit-3");
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
        runReader("file-error");
        FAIL() << "no error";
    } catch (const ImportError& error) {
        FAIL() << "an ImportError: " << error.what();
    } catch (const FileError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "/nonexistent/scene.ply: cannot read PLY file: no faces");
    }
}

TEST(ReaderProcess, TheSceneComesBackEqual)
{
    const ReaderResult sent = testReaderScene();
    const SceneMesh& mesh = sent.scene.meshes[0];
    const SceneNode& child = sent.scene.nodes[1];
    const ReaderResult got = runReader("scene");
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
    // Until the reader has started (over 100 ms for a sanitized build) the runner re-reports 0.
    std::vector<double> reports;
    int sinceReaderReported = 0;
    ImportOptions options;
    options.progress = [&](double fraction) {
        reports.push_back(fraction);
        if (fraction >= 0.25) ++sinceReaderReported;
        return sinceReaderReported < 3;
    };
    const auto start = std::chrono::steady_clock::now();
    EXPECT_THROW(runReader("silent", options), Cancelled);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(sinceReaderReported, 3);
    EXPECT_EQ(*std::find_if(reports.begin(), reports.end(), [](double f) { return f > 0.0; }),
              0.25);
    EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
    // Not a timing assertion on the machine's speed: the reader alone would take 60 s.
    EXPECT_LT(seconds, 30.0) << "the cancel waited for the silent reader";
}

TEST(ReaderProcess, TheOptionsReachTheReaderExactly)
{
    ImportOptions options;
    options.metresPerUnit = 0.1 + 1e-17 * 3; // not a short decimal
    options.upAxis = UpAxis::PositiveZ;
    options.chordalTolerance = 1.0 / 3.0;
    options.angularTolerance = 0.7853981633974483;
    const ReaderResult got = runReader("options", options);
    EXPECT_EQ(got.metresPerReaderUnit, *options.metresPerUnit);
    EXPECT_EQ(got.sourceUnitsPerReaderUnit, options.chordalTolerance);
    EXPECT_EQ(got.scene.sourceUnits.metresPerUnit, options.angularTolerance);
    EXPECT_EQ(got.scene.format, "z");
    EXPECT_EQ(runReader("options").scene.format, "-");
    EXPECT_EQ(runReader("options").metresPerReaderUnit, -1.0);
}

TEST(ReaderProcess, AMissingReaderProgramIsAFileErrorNamingIt)
{
    ImportOptions options;
    ProgressStage stage(options, kFile, 0.0, 1.0);
    try {
        static_cast<void>(readInChildProcess(kFile, "test reader", options, stage,
                                             {"/nonexistent/chaintube-scene-reader", {}}));
        FAIL() << "no error";
    } catch (const FileError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "/nonexistent/scene.ply: cannot start the importer process "
                  "/nonexistent/chaintube-scene-reader: No such file or directory");
    }
}

/// Runs `command` in a shell; its exit status and what it wrote (stdout and stderr).
std::pair<int, std::string> runCommand(const std::string& command)
{
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return {-1, "popen failed"};
    std::string said;
    char chunk[256];
    while (std::fgets(chunk, sizeof chunk, pipe))
        said += chunk;
    const int status = ::pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, said};
}

TEST(ReaderProcess, ReadersAreFoundInChaintubeReadersDir)
{
    // An installation elsewhere: the readers in a folder of their own, named by the variable.
    namespace fs = std::filesystem;
    const fs::path folder =
        fs::temp_directory_path() / ("chaintube-readers-" + std::to_string(::getpid()));
    fs::create_directories(folder);
    fs::copy_file(CHAINTUBE_SCENE_READER_PROGRAM, folder / "chaintube-scene-reader");
    {
        std::ofstream(folder / "quad.obj")
            << "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    }
    ::setenv("CHAINTUBE_READERS_DIR", folder.c_str(), 1);
    EXPECT_EQ(readerProgram("chaintube-scene-reader", folder / "quad.obj"),
              folder / "chaintube-scene-reader");
    EXPECT_EQ(importScene(folder / "quad.obj").meshTriangleCount(), 2u);
    fs::remove(folder / "chaintube-scene-reader");
    try {
        static_cast<void>(importScene(folder / "quad.obj"));
        ADD_FAILURE() << "imported without a reader program";
    } catch (const FileError& error) {
        EXPECT_NE(
            std::string(error.what()).find("which holds no executable chaintube-scene-reader"),
            std::string::npos)
            << error.what();
    }
    ::unsetenv("CHAINTUBE_READERS_DIR");
    fs::remove_all(folder);
}

TEST(ReaderProcess, TheSceneReaderStartedByHandSaysWhatItIs)
{
    const auto [status, said] = runCommand(CHAINTUBE_SCENE_READER_PROGRAM);
    EXPECT_EQ(status, 122);
    EXPECT_NE(said.find("expected at least 8 arguments, got 0"), std::string::npos) << said;
    EXPECT_NE(said.find("not meant to be run by hand"), std::string::npos) << said;
}

TEST(ReaderProcess, AReaderOfAnotherProtocolRefusesToAnswer)
{
    const auto [status, said] = runCommand(std::string(CHAINTUBE_SCENE_READER_PROGRAM) +
                                           " .ply chaintube-scene-reader-protocol-0 /x.ply 1 - - "
                                           "0x1p-10 0x1p-1 0");
    EXPECT_EQ(status, 122);
    EXPECT_NE(said.find("this program speaks chaintube-scene-reader-protocol-1, its caller "
                        "chaintube-scene-reader-protocol-0"),
              std::string::npos)
        << said;
}

} // namespace
} // namespace chaintube::formats::detail
