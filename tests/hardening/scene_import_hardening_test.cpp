// Scene files that made a third-party reader hang are refused by formats::importScene with a
// clear error within a bounded time (each import runs in a forked child that is killed after
// the limit, so a regression fails this test instead of blocking the suite). Files that make
// assimp crash are an ImportError and the calling program goes on (importScene runs assimp in
// a child process of its own).
#include "bounded_child.h"

#include <chaintube/formats/scene_import.h>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <random>
#include <thread>

namespace chaintube::hardening {
namespace {

namespace fs = std::filesystem;

struct ImportOutcome
{
    ChildOutcome child;
    bool refused() const { return child.finished && child.exitCode == 1; }
    bool imported() const { return child.finished && child.exitCode == 0; }
};

/// importScene(file) in a child: exit 0 imported, 1 refused with chaintube::Error (message
/// written back), 2 any other exception.
ImportOutcome importWithin(const fs::path& file, std::chrono::seconds limit)
{
    ImportOutcome outcome;
    outcome.child = runInChild(
        [&](const std::function<void(const std::string&)>& write) {
            try {
                static_cast<void>(formats::importScene(file));
                return 0;
            } catch (const Error& error) {
                write(error.what());
                return 1;
            } catch (const std::exception& error) {
                write(error.what());
                return 2;
            }
        },
        limit);
    return outcome;
}

class ScratchFolder
{
public:
    ScratchFolder()
        : m_path(fs::temp_directory_path() /
                 ("chaintube-hardening-" + std::to_string(std::random_device{}())))
    {
        fs::create_directories(m_path);
    }
    ~ScratchFolder() { fs::remove_all(m_path); }
    fs::path write(const std::string& name, const std::string& text) const
    {
        std::ofstream(m_path / name, std::ios::binary) << text;
        return m_path / name;
    }

private:
    fs::path m_path;
};

const fs::path badScenes = fs::path(CHAINTUBE_BAD_DATA_DIR) / "scene";

TEST(SceneImportHardening, PlyWhoseHeaderNeverEndsIsRefusedWithoutHanging)
{
    // The fuzzer's finding (tests/fuzz/findings/assimp-ply-hang.bin without its format byte):
    // assimp 5.2.5 loops forever on it. The message shows it was refused by the header check
    // before assimp saw it (not by a time-out); the 20 s bound only stops a hang.
    const fs::path file = badScenes / "ply-without-end-header.ply";
    const ImportOutcome outcome = importWithin(file, std::chrono::seconds(20));
    ASSERT_TRUE(outcome.child.finished) << "importScene did not return within 20 s";
    std::printf("refused after %.3f s\n", outcome.child.seconds);
    EXPECT_TRUE(outcome.refused()) << "exit " << outcome.child.exitCode;
    EXPECT_EQ(outcome.child.message,
              file.string() + ": malformed PLY: the header has no 'end_header' line");
}

TEST(SceneImportHardening, PlyHeadersThatStopEarlyAreRefusedNotHung)
{
    ScratchFolder folder;
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n";
    for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
             {"binary-header-only.ply",
              "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"},
             {"element-at-end.ply",
              header + "property float y\nproperty float z\nelement vertex 3\n"},
             {"crlf-no-end.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 1\r\n"},
             {"magic-only.ply", "ply"},
             {"end-header-in-a-comment.ply", header + "comment end_header\n0\n0\n0\n"}}) {
        const ImportOutcome outcome =
            importWithin(folder.write(name, text), std::chrono::seconds(20));
        ASSERT_TRUE(outcome.child.finished) << name << ": importScene did not return within 20 s";
        EXPECT_TRUE(outcome.refused()) << name << ": exit " << outcome.child.exitCode;
        EXPECT_NE(outcome.child.message.find("malformed PLY: the header has no 'end_header' line"),
                  std::string::npos)
            << name << ": " << outcome.child.message;
    }
    const ImportOutcome notPly =
        importWithin(folder.write("not-ply.ply", "solid x\n"), std::chrono::seconds(20));
    EXPECT_TRUE(notPly.refused());
    EXPECT_NE(notPly.child.message.find("malformed PLY: the first line must be 'ply'"),
              std::string::npos)
        << notPly.child.message;
}

TEST(SceneImportHardening, PlyBodyShorterThanItsHeaderIsRefusedBeforeAssimpAborts)
{
    // scene_import_fuzzer, seed 1: assimp 5.2.5's TriangulateProcess aborts (ai_assert) on it.
    ScratchFolder folder;
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n";
    const ImportOutcome ascii =
        importWithin(folder.write("short.ply", header + "00 1 2\n"), std::chrono::seconds(20));
    ASSERT_TRUE(ascii.child.finished);
    EXPECT_TRUE(ascii.refused()) << "exit " << ascii.child.exitCode;
    EXPECT_NE(ascii.child.message.find(
                  "malformed PLY: the header declares 10 or more values, the body holds 3"),
              std::string::npos)
        << ascii.child.message;
    const std::string binaryHeader =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n";
    const ImportOutcome binary =
        importWithin(folder.write("short-binary.ply", binaryHeader + std::string(20, '\0')),
                     std::chrono::seconds(20));
    ASSERT_TRUE(binary.child.finished);
    EXPECT_TRUE(binary.refused());
    EXPECT_NE(binary.child.message.find("declares 36 or more bytes of data, the body has 20"),
              std::string::npos)
        << binary.child.message;
}

TEST(SceneImportHardening, PlyElementCountsAssimpWouldMisreadAreRefusedBeforeAllocating)
{
    // scene_import_fuzzer (tests/fuzz/findings/assimp-ply-element-name-digits-21gb.bin without
    // its format byte): assimp 5.2.5 read the digits of the element name "6666666666666vertex"
    // as its count and asked for 21 GB.
    ScratchFolder folder;
    const std::string rest = " 3\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\n"
                             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const fs::path named =
        folder.write("name.ply", "ply\nformat ascii 1.0\nelement 6666666666666vertex" + rest);
    const ImportOutcome name = importWithin(named, std::chrono::seconds(20));
    ASSERT_TRUE(name.child.finished) << "importScene did not return within 20 s";
    EXPECT_TRUE(name.refused()) << "exit " << name.child.exitCode;
    EXPECT_EQ(name.child.message,
              named.string() + ": malformed PLY: element name '6666666666666vertex': expected a "
                               "name that does not start with a digit");
    // A count with something glued to it, and one of 13 digits (more than any file holds).
    const fs::path glued = folder.write("glued.ply", "ply\nformat ascii 1.0\nelement vertex 3x" +
                                                         rest.substr(2)); // " 3" replaced by "3x"
    const ImportOutcome gluedOutcome = importWithin(glued, std::chrono::seconds(20));
    ASSERT_TRUE(gluedOutcome.child.finished);
    EXPECT_TRUE(gluedOutcome.refused()) << "exit " << gluedOutcome.child.exitCode;
    EXPECT_EQ(gluedOutcome.child.message,
              glued.string() + ": malformed PLY: element 'vertex' has count '3x': expected a "
                               "whole number");
    const ImportOutcome huge = importWithin(
        folder.write("huge.ply",
                     "ply\nformat ascii 1.0\nelement vertex 6666666666666" + rest.substr(2)),
        std::chrono::seconds(20));
    ASSERT_TRUE(huge.child.finished);
    EXPECT_TRUE(huge.refused()) << "exit " << huge.child.exitCode;
    EXPECT_NE(huge.child.message.find("malformed PLY: the header declares"), std::string::npos)
        << huge.child.message;
}

TEST(SceneImportHardening, OffDeclaringMoreVerticesThanItsBytesIsRefusedBeforeAllocating)
{
    // The fuzzer's finding: 115 bytes declaring 4.4e31 vertices made assimp 5.2.5 ask for
    // 5.7 GB.
    const fs::path file = badScenes / "off-vertex-count-too-large.off";
    const ImportOutcome outcome = importWithin(file, std::chrono::seconds(20));
    ASSERT_TRUE(outcome.child.finished) << "importScene did not return within 20 s";
    EXPECT_TRUE(outcome.refused()) << "exit " << outcome.child.exitCode;
    EXPECT_NE(outcome.child.message.find(file.string() + ": malformed OFF: the header declares "),
              std::string::npos)
        << outcome.child.message;
    EXPECT_NE(outcome.child.message.find("vertices, more than a file of 114 bytes can hold"),
              std::string::npos)
        << outcome.child.message;

    // The second: "OFF" with the count glued to it; assimp reads the digits anyway (wrapping
    // them to 1.1e9 vertices) and filled 13 GB for a file of 73 bytes.
    const fs::path glued = badScenes / "off-count-glued-to-keyword.off";
    const ImportOutcome gluedOutcome = importWithin(glued, std::chrono::seconds(20));
    ASSERT_TRUE(gluedOutcome.child.finished) << "importScene did not return within 20 s";
    EXPECT_TRUE(gluedOutcome.refused()) << "exit " << gluedOutcome.child.exitCode;
    EXPECT_EQ(gluedOutcome.child.message,
              glued.string() + ": malformed OFF: the header declares "
                               "00000000000002000000000000000000000000 vertices, more than a file "
                               "of 73 bytes can hold");

    ScratchFolder folder;
    const ImportOutcome glued3 =
        importWithin(folder.write("glued.off", "OFF3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                     std::chrono::seconds(20));
    EXPECT_TRUE(glued3.imported()) << glued3.child.message; // a small glued count is assimp's
    const ImportOutcome faces = importWithin(
        folder.write("faces.off", "OFF\n# comment\n3 99999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
        std::chrono::seconds(20));
    EXPECT_TRUE(faces.refused());
    EXPECT_NE(faces.child.message.find("declares 99999 faces"), std::string::npos)
        << faces.child.message;
    const ImportOutcome fine =
        importWithin(folder.write("triangle.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                     std::chrono::seconds(20));
    EXPECT_TRUE(fine.imported()) << fine.child.message;
}

TEST(SceneImportHardening, PlyFaceWithoutIndicesThatAbortsAssimpIsAnImportErrorAndTheProgramGoesOn)
{
    // The fuzzer's finding (tests/fuzz/findings/assimp-ply-triangulate-abort.bin without its
    // format byte): the face line "FF" gives a face with no indices, on which an ai_assert in
    // Debian's assimp 5.2.5 (TriangulateProcess) aborts. Imported in this very process: the
    // abort ends the importer's child process, not this one.
    const fs::path file = badScenes / "ply-face-without-indices.ply";
    try {
        static_cast<void>(formats::importScene(file));
        FAIL() << "importScene accepted " << file;
    } catch (const formats::ImportError& error) {
        EXPECT_EQ(std::string(error.what()),
                  file.string() + ": the PLY importer (assimp) crashed on malformed data (signal " +
                      std::to_string(SIGABRT) +
                      ", SIGABRT: Aborted); it wrote: ai_assert failure in "
                      "./code/PostProcessing/TriangulateProcess.cpp(238): numOut != "
                      "pMesh->mNumFaces");
        EXPECT_EQ(error.file(), file);
        EXPECT_EQ(error.signal(), SIGABRT);
        EXPECT_EQ(error.exitStatus(), -1);
        EXPECT_NE(error.readerOutput().find("ai_assert failure"), std::string::npos)
            << error.readerOutput();
    }
    // The same process imports the next file as if nothing had happened.
    ScratchFolder folder;
    const formats::ImportedScene scene = formats::importScene(
        folder.write("triangle.obj", "o tri\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    EXPECT_EQ(scene.meshTriangleCount(), 1u);
}

TEST(SceneImportHardening, ImportsFromSeveralThreadsAtOnceEachGetTheirOwnAnswer)
{
    // The editor imports on a worker thread while others run: every import starts its own
    // reader program, and no import's pipe may stay open in another's reader (it would hold
    // back that import's end of file) or hand it the wrong answer. With fork() alone instead of
    // a fresh program, this test hung under ASan in CI: a forked copy inherited an allocator
    // lock another thread held.
    ScratchFolder folder;
    const fs::path good =
        folder.write("quad.obj", "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    const fs::path crashing = badScenes / "ply-face-without-indices.ply";
    constexpr int kThreads = 4, kRounds = 10;
    std::vector<std::string> failures(kThreads);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            for (int round = 0; round < kRounds; ++round) {
                if ((t + round) % 2 == 0) {
                    try {
                        const formats::ImportedScene scene = formats::importScene(good);
                        if (scene.meshTriangleCount() != 2)
                            failures[t] +=
                                "quad.obj: " + std::to_string(scene.meshTriangleCount()) +
                                " triangles, expected 2; ";
                    } catch (const std::exception& error) {
                        failures[t] += std::string("quad.obj: ") + error.what() + "; ";
                    }
                } else {
                    try {
                        static_cast<void>(formats::importScene(crashing));
                        failures[t] += "the crashing PLY was accepted; ";
                    } catch (const formats::ImportError& error) {
                        if (error.signal() != SIGABRT)
                            failures[t] += std::string("crashing PLY: ") + error.what() + "; ";
                    }
                }
            }
        });
    }
    for (std::thread& thread : threads)
        thread.join();
    for (int t = 0; t < kThreads; ++t)
        EXPECT_EQ(failures[t], "") << "thread " << t;
}

TEST(SceneImportHardening, WellFormedPlyStillImports)
{
    ScratchFolder folder;
    const std::string body = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\n";
    for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
             {"triangle.ply", body + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
             {"triangle-crlf.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\n"
                                   "property float x\r\nproperty float y\r\nproperty float z\r\n"
                                   "element face 1\r\nproperty list uchar int vertex_indices\r\n"
                                   "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n"}}) {
        const ImportOutcome outcome =
            importWithin(folder.write(name, text), std::chrono::seconds(20));
        EXPECT_TRUE(outcome.imported())
            << name << ": exit " << outcome.child.exitCode << " " << outcome.child.message;
    }
}

} // namespace
} // namespace chaintube::hardening
