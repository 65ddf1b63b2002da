// Project paths never leave the project's folder (or a named root) unless written absolute.
#include "chaintube/formats/paths.h"
#include "test_files.h"

#include <gtest/gtest.h>

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

} // namespace
} // namespace chaintube::formats
