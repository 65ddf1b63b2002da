// `chaintube info`: per hose gravity on/off and direction, torsion on/off and twist
// limit, and the project's / descriptor's collider objects, read from the real CLI's output.
#include "cli_run.h"
#include "export_test_support.h"

#include <array>
#include <cstdio>
#include <sys/wait.h>

namespace chaintube::exporting::testing {
namespace {

/// The lines `info` prints for hose `id` (from its "hose 'id'" line to the next hose).
std::string hoseBlock(const std::string& output, const std::string& id)
{
    const size_t start = output.find("hose '" + id + "'");
    if (start == std::string::npos) return {};
    const size_t end = output.find("\nhose '", start + 1);
    return output.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

const fs::path kRigOptions = fs::path(CHAINTUBE_EXPORT_TEST_DATA_DIR) / "rig-options.ctproj";
const std::string kRoots = std::string("--root samples=\"") + CHAINTUBE_SAMPLES_DIR + "\"";

TEST(InfoCli, ProjectListsGravityTorsionPerHoseAndTheColliderObjects)
{
    const CliRun run = runCli("info \"" + kRigOptions.string() + "\" " + kRoots);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("colliders: 2 — scene 'rig' node /test-rig/floor_plate, scene 'rig' "
                              "node /test-rig/valve\n"),
              std::string::npos)
        << run.output;
    const std::string pipe = hoseBlock(run.output, "pipe-on-plate");
    const std::string tail = hoseBlock(run.output, "valve-tail");
    const std::string loop = hoseBlock(run.output, "bracket-loop");
    ASSERT_FALSE(pipe.empty() || tail.empty() || loop.empty()) << run.output;
    EXPECT_NE(pipe.find("  gravity: off\n"), std::string::npos) << pipe;
    EXPECT_NE(pipe.find("  torsion: off\n"), std::string::npos) << pipe;
    EXPECT_NE(tail.find("  gravity: on, direction (0, -1, 0)\n"), std::string::npos) << tail;
    EXPECT_NE(tail.find("  torsion: off\n"), std::string::npos) << tail;
    EXPECT_NE(loop.find("  gravity: off\n"), std::string::npos) << loop;
    EXPECT_NE(loop.find("  torsion: on, twist limit 0.2 rad (11.46°) per joint\n"),
              std::string::npos)
        << loop;
}

TEST(InfoCli, ProjectWithoutCollidersSaysSo)
{
    const CliRun run = runCli(
        "info \"" + (fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj").string() + "\"");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("\ncolliders: 0\n"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("  gravity: off\n  torsion: off\n"), std::string::npos) << run.output;
}

TEST(InfoCli, ExportedRigListsTheSameFlagsAndNamesTheColliderNodes)
{
    TemporaryFolder folder;
    const fs::path glb = folder.path() / "rig-options.glb";
    const CliRun exported =
        runCli("export \"" + kRigOptions.string() + "\" -o \"" + glb.string() + "\" -q " + kRoots);
    ASSERT_EQ(exported.exitCode, 0) << exported.output;
    for (const fs::path& file : {glb, fs::path(folder.path() / "rig-options.hoses.json")}) {
        const CliRun run = runCli("info \"" + file.string() + "\"");
        ASSERT_EQ(run.exitCode, 0) << run.output;
        const bool gltf = file.extension() == ".glb";
        EXPECT_NE(run.output.find("colliders: 2 — node "), std::string::npos) << run.output;
        if (gltf) { // the glTF names its nodes; the bare descriptor knows only their indices
            EXPECT_NE(run.output.find("'floor_plate'"), std::string::npos) << run.output;
            EXPECT_NE(run.output.find("'valve'"), std::string::npos) << run.output;
        }
        EXPECT_NE(hoseBlock(run.output, "valve-tail").find("  gravity: on, direction (0, -1, 0)\n"),
                  std::string::npos)
            << run.output;
        EXPECT_NE(hoseBlock(run.output, "bracket-loop")
                      .find("  torsion: on, twist limit 0.2 rad (11.46°) per joint\n"),
                  std::string::npos)
            << run.output;
    }
}

TEST(InfoCli, ExportedRigListsItsMovingPartsWithTheirNodesAndRanges)
{
    TemporaryFolder folder;
    const fs::path glb = folder.path() / "motion-rig.glb";
    const CliRun exported =
        runCli("export \"" + (fs::path(CHAINTUBE_SAMPLES_DIR) / "motion-rig.ctproj").string() +
               "\" -o \"" + glb.string() + "\" -q");
    ASSERT_EQ(exported.exitCode, 0) << exported.output;
    const CliRun run = runCli("info \"" + glb.string() + "\"");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("hose rig 1.5 "), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("\nmotions: 2 — lever (hinge of node "), std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find(" 'lever', -0.5 … 0.8 rad), carriage (slider of node "),
              std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find(" 'carriage', -0.05 … 0.05 m)\n"), std::string::npos) << run.output;
    const CliRun older = runCli(
        "info \"" + (fs::path(CHAINTUBE_SAMPLES_DIR) / "single-hose.ctproj").string() + "\"");
    ASSERT_EQ(older.exitCode, 0) << older.output;
}

TEST(InfoCli, ProjectAndExportedRigListTheirSocketsAndPlugs)
{
    TemporaryFolder folder;
    const fs::path project = fs::path(CHAINTUBE_SAMPLES_DIR) / "test-rig.ctproj";
    const fs::path glb = folder.path() / "test-rig.glb";
    const CliRun exported =
        runCli("export \"" + project.string() + "\" -o \"" + glb.string() + "\" -q");
    ASSERT_EQ(exported.exitCode, 0) << exported.output;
    for (const fs::path& file : {project, glb}) {
        const CliRun run = runCli("info \"" + file.string() + "\"");
        ASSERT_EQ(run.exitCode, 0) << run.output;
        EXPECT_NE(run.output.find("\nsockets: 2 — valve-outlet (tag 'camlock-19', "),
                  std::string::npos)
            << run.output;
        EXPECT_NE(run.output.find("), plate-port (tag 'camlock-19', "), std::string::npos)
            << run.output;
        EXPECT_NE(hoseBlock(run.output, "left-feed").find("  plugs: start —, end 'camlock-19'"),
                  std::string::npos)
            << run.output;
    }
    const CliRun none = runCli("info \"" + kRigOptions.string() + "\" " + kRoots);
    ASSERT_EQ(none.exitCode, 0) << none.output;
    EXPECT_NE(none.output.find("\nsockets: 0\n"), std::string::npos) << none.output;
}

TEST(InfoCli, HelpNamesGravityTorsionAndColliders)
{
    const CliRun run = runCli("info --help");
    EXPECT_EQ(run.exitCode, 0) << run.output;
    for (const char* word : {"gravity", "torsion", "collider"})
        EXPECT_NE(run.output.find(word), std::string::npos) << word << " missing:\n" << run.output;
}

} // namespace
} // namespace chaintube::exporting::testing
