// Project paths never leave the project's folder (or a named root) unless written absolute.
#include "chaintube/formats/paths.h"
#include "test_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using testing::TemporaryFolder;

class ProjectPaths : public ::testing::Test
{
protected:
    void SetUp() override
    {
        fs::create_directories(folder / "project/scenes");
        fs::create_directories(folder / "outside");
        fs::create_directories(folder / "library/cad");
        testing::writeText(folder / "project/scenes/rig.gltf", "{}");
        testing::writeText(folder / "outside/secret.glb", "x");
        testing::writeText(folder / "library/cad/engine.glb", "x");
    }
    fs::path project() const { return folder / "project"; }
    TemporaryFolder folder;
    NamedRoots roots{{"lib", folder / "library"}};
};

TEST_F(ProjectPaths, RelativePathInsideTheProjectResolves)
{
    EXPECT_EQ(resolveProjectPath("scenes/rig.gltf", project(), roots),
              fs::weakly_canonical(project() / "scenes/rig.gltf"));
    EXPECT_EQ(resolveProjectPath("scenes/../scenes/rig.gltf", project(), roots),
              fs::weakly_canonical(project() / "scenes/rig.gltf"));
}

TEST_F(ProjectPaths, DotDotOutOfTheProjectIsRefused)
{
    EXPECT_THROW(resolveProjectPath("../outside/secret.glb", project(), roots), PathError);
    EXPECT_THROW(resolveProjectPath("scenes/../../outside/secret.glb", project(), roots),
                 PathError);
    try {
        resolveProjectPath("../outside/secret.glb", project(), roots);
    } catch (const PathError& error) {
        EXPECT_NE(std::string(error.what()).find("leaves the project's folder"), std::string::npos)
            << error.what();
    }
}

TEST_F(ProjectPaths, SymlinkInsideTheProjectPointingOutsideIsRefused)
{
    fs::create_directory_symlink(folder / "outside", project() / "linked");
    fs::create_symlink(folder / "outside/secret.glb", project() / "scenes/innocent.glb");
    EXPECT_THROW(resolveProjectPath("linked/secret.glb", project(), roots), PathError);
    EXPECT_THROW(resolveProjectPath("scenes/innocent.glb", project(), roots), PathError);
}

TEST_F(ProjectPaths, SymlinkStayingInsideTheProjectIsFine)
{
    fs::create_directory_symlink(project() / "scenes", project() / "alias");
    EXPECT_EQ(resolveProjectPath("alias/rig.gltf", project(), roots),
              fs::weakly_canonical(project() / "scenes/rig.gltf"));
}

TEST_F(ProjectPaths, AbsolutePathsAreTheUsersExplicitChoice)
{
    const fs::path absolute = folder / "outside/secret.glb";
    EXPECT_EQ(classifyProjectPath(absolute.string()), PathKind::Absolute);
    EXPECT_EQ(resolveProjectPath(absolute.string(), project(), roots),
              fs::weakly_canonical(absolute));
}

TEST_F(ProjectPaths, NamedRootsResolveAndMayNotBeEscaped)
{
    EXPECT_EQ(classifyProjectPath("lib:cad/engine.glb"), PathKind::NamedRoot);
    EXPECT_EQ(resolveProjectPath("lib:cad/engine.glb", project(), roots),
              fs::weakly_canonical(folder / "library/cad/engine.glb"));
    EXPECT_THROW(resolveProjectPath("lib:../outside/secret.glb", project(), roots), PathError);
    EXPECT_THROW(resolveProjectPath("lib:/etc/passwd", project(), roots), PathError);
}

TEST_F(ProjectPaths, UnknownRootNamesTheKnownOnes)
{
    try {
        resolveProjectPath("assets:engine.glb", project(), roots);
        FAIL() << "no PathError";
    } catch (const PathError& error) {
        EXPECT_NE(std::string(error.what()).find("unknown named root 'assets' (known: lib)"),
                  std::string::npos)
            << error.what();
    }
}

TEST_F(ProjectPaths, MalformedPathsAreRefused)
{
    EXPECT_THROW(classifyProjectPath(""), PathError);
    EXPECT_THROW(classifyProjectPath("scenes\\rig.gltf"), PathError);
    EXPECT_EQ(classifyProjectPath("a:b"), PathKind::Relative) << "one letter is not a root name";
}

TEST_F(ProjectPaths, AFileIsWrittenRelativeInsideTheProjectUnderARootOrElseAbsolute)
{
    EXPECT_EQ(projectPathFor(project() / "scenes/rig.gltf", project(), roots), "scenes/rig.gltf");
    EXPECT_EQ(projectPathFor(folder / "library/cad/engine.glb", project(), roots),
              "lib:cad/engine.glb");
    const std::string outside = projectPathFor(folder / "outside/secret.glb", project(), roots);
    EXPECT_EQ(classifyProjectPath(outside), PathKind::Absolute) << outside;
    EXPECT_EQ(resolveProjectPath(outside, project(), roots),
              fs::weakly_canonical(folder / "outside/secret.glb"));
    // No project folder yet (an untitled project): absolute unless under a root.
    EXPECT_EQ(classifyProjectPath(projectPathFor(project() / "scenes/rig.gltf", {}, roots)),
              PathKind::Absolute);
}

TEST_F(ProjectPaths, RebasingKeepsNamingTheSameFileFromTheNewFolder)
{
    const fs::path original = fs::weakly_canonical(project() / "scenes/rig.gltf");
    // Up one folder: still inside, so still relative.
    EXPECT_EQ(rebaseProjectPath("scenes/rig.gltf", project(), folder.path()),
              "project/scenes/rig.gltf");
    // Into a sibling folder: outside it, so absolute.
    const std::string sibling = rebaseProjectPath("scenes/rig.gltf", project(), folder / "outside");
    EXPECT_EQ(classifyProjectPath(sibling), PathKind::Absolute) << sibling;
    EXPECT_EQ(resolveProjectPath(sibling, folder / "outside", roots), original);
    // And back: relative again, exactly as written.
    EXPECT_EQ(rebaseProjectPath(sibling, folder / "outside", project()), "scenes/rig.gltf");
    // Into a deeper folder of the project: the file is not inside it, so absolute.
    fs::create_directories(project() / "deeper");
    EXPECT_EQ(
        classifyProjectPath(rebaseProjectPath("scenes/rig.gltf", project(), project() / "deeper")),
        PathKind::Absolute);
    // A file that does not exist (yet) is rebased the same way.
    EXPECT_EQ(rebaseProjectPath("export/rig.glb", project(), folder.path()),
              "project/export/rig.glb");
}

TEST_F(ProjectPaths, RebasingToAnotherRootAndBackGivesTheWrittenPathBack)
{
    // A folder outside the temporary folder's tree (the tests' working folder, in the build
    // tree): the way a project moves to another disk.
    const fs::path other = fs::current_path() / ("rebase-other-root-" + std::to_string(::getpid()));
    fs::create_directories(other);
    const std::string there = rebaseProjectPath("scenes/rig.gltf", project(), other);
    EXPECT_EQ(classifyProjectPath(there), PathKind::Absolute) << there;
    EXPECT_EQ(resolveProjectPath(there, other, roots),
              fs::weakly_canonical(project() / "scenes/rig.gltf"));
    EXPECT_EQ(rebaseProjectPath(there, other, project()), "scenes/rig.gltf");
    fs::remove_all(other);
}

TEST_F(ProjectPaths, RebasingLeavesNamedRootsSameFolderAndForeignAbsolutePathsAlone)
{
    EXPECT_EQ(rebaseProjectPath("lib:cad/engine.glb", project(), folder / "outside"),
              "lib:cad/engine.glb");
    EXPECT_EQ(rebaseProjectPath("scenes/../scenes/rig.gltf", project(), project() / "."),
              "scenes/../scenes/rig.gltf")
        << "the same folder: nothing changes";
    const std::string absolute = (folder / "library/cad/engine.glb").string();
    EXPECT_EQ(rebaseProjectPath(absolute, project(), folder / "outside"), absolute);
    EXPECT_THROW(rebaseProjectPath("../outside/secret.glb", project(), folder.path()), PathError)
        << "a relative path that already leaves its folder is an error, not rebased";
}

} // namespace
} // namespace chaintube::formats
