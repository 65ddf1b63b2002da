// A project saved into another folder (formats::rebaseProject, what the editor's Save As calls)
// opens in the real `chaintube` CLI from there: in a sibling folder, under another root (the
// build tree instead of the temporary folder) and back in its own folder as it was written.
#include "cli_run.h"
#include "export_test_support.h"

#include <chaintube/formats/project.h>
#include <chaintube/test_support/files.h>
#include <gtest/gtest.h>
#include <unistd.h>

namespace chaintube::exporting::testing {
namespace {

namespace fs = std::filesystem;

/// Saves `project`, read from `from`, at `to` as Save As does.
formats::Project saveAs(const formats::Project& project, const fs::path& from, const fs::path& to)
{
    formats::Project moved = formats::rebaseProject(project, from, to);
    fs::create_directories(to.parent_path());
    formats::saveProject(moved, to);
    return moved;
}

/// The CLI opens `file`, imports its scene and checks its hoses: exit 0 (no violation) or 3
/// (violations found), never 1 (the check could not run).
void expectTheCliOpens(const fs::path& file)
{
    const CliRun check = runCli("check \"" + file.string() + "\" --clearance 0.001");
    EXPECT_TRUE(check.exitCode == 0 || check.exitCode == 3) << "exit " << check.exitCode << "\n"
                                                            << check.output;
    EXPECT_EQ(check.output.find("no such file"), std::string::npos) << check.output;
    const CliRun info = runCli("info \"" + file.string() + "\"");
    EXPECT_EQ(info.exitCode, 0) << info.output;
    EXPECT_NE(info.output.find("left-feed"), std::string::npos) << info.output;
    const CliRun validate = runCli("validate \"" + file.string() + "\"");
    EXPECT_EQ(validate.exitCode, 0) << validate.output;
}

TEST(SaveAsCli, AProjectSavedIntoAnotherFolderOrRootAndBackOpensInTheCli)
{
    test_support::TemporaryFolder folder;
    const fs::path original = folder / "rig/test-rig.ctproj";
    fs::create_directories(folder / "rig/scenes");
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "rig/scenes/test-rig.gltf");
    formats::Project project = formats::loadProject(samplesDir() / "test-rig.ctproj");
    ASSERT_EQ(project.scenes.at(0).path, "scenes/test-rig.gltf");
    project.exportSettings.path = "out/test-rig.glb";
    formats::saveProject(project, original);
    const std::string originalText = test_support::readText(original);
    expectTheCliOpens(original);
    const fs::path scene = fs::weakly_canonical(folder / "rig/scenes/test-rig.gltf");
    const fs::path target = fs::weakly_canonical(folder / "rig") / "out/test-rig.glb";

    // Another folder beside it: the scene and the export target named absolutely.
    const fs::path sibling = folder / "elsewhere/deeper/copy.ctproj";
    const formats::Project there = saveAs(project, original, sibling);
    EXPECT_TRUE(fs::path(there.scenes[0].path).is_absolute()) << there.scenes[0].path;
    EXPECT_EQ(formats::resolveScenePath(formats::loadProject(sibling).scenes[0], sibling, {}),
              scene);
    EXPECT_EQ(formats::resolveProjectPath(there.exportSettings.path, sibling.parent_path(), {}),
              target);
    expectTheCliOpens(sibling);

    // Another root: a folder in the build tree, not under the temporary folder.
    const fs::path otherRoot =
        fs::current_path() / ("save-as-other-root-" + std::to_string(::getpid()));
    const fs::path moved = otherRoot / "moved.ctproj";
    const formats::Project onOtherRoot = saveAs(formats::loadProject(sibling), sibling, moved);
    EXPECT_EQ(formats::resolveScenePath(onOtherRoot.scenes[0], moved, {}), scene);
    expectTheCliOpens(moved);

    // And back into its own folder: the paths are relative again, the file as it was.
    saveAs(formats::loadProject(moved), moved, original);
    EXPECT_EQ(test_support::readText(original), originalText);
    expectTheCliOpens(original);

    // Into the parent folder: still inside, so relative through the subfolder.
    const fs::path parent = folder / "parent.ctproj";
    const formats::Project up = saveAs(formats::loadProject(original), original, parent);
    EXPECT_EQ(up.scenes[0].path, "rig/scenes/test-rig.gltf");
    EXPECT_EQ(up.exportSettings.path, "rig/out/test-rig.glb");
    expectTheCliOpens(parent);
    fs::remove_all(otherRoot);
}

} // namespace
} // namespace chaintube::exporting::testing
