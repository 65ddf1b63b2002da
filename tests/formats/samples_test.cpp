// Every committed sample loads, is canonical (load → save is byte for byte the same), and
// survives save → load unchanged.
#include "chaintube/formats/project.h"
#include "test_files.h"

#include <gtest/gtest.h>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;

fs::path samplesFolder()
{
    return CHAINTUBE_SAMPLES_DIR;
}

ProjectLoadOptions sampleOptions()
{
    return {{{"scenes", fs::path(CHAINTUBE_SCENES_DIR)}}};
}

std::vector<fs::path> sampleFiles()
{
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(samplesFolder()))
        if (entry.path().extension() == kProjectExtension) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

TEST(Samples, TheDocumentedSamplesExist)
{
    for (const char* name : {"single-hose.ctproj", "engine.ctproj", "engine-50-hoses.ctproj",
                             "test-rig.ctproj", "motion-rig.ctproj"})
        EXPECT_TRUE(fs::exists(samplesFolder() / name)) << name;
    EXPECT_GE(sampleFiles().size(), 5u);
}

TEST(Samples, EverySampleIsCanonicalAndRoundTripsExactly)
{
    testing::TemporaryFolder folder;
    for (const fs::path& sample : sampleFiles()) {
        SCOPED_TRACE(sample.filename().string());
        const Project project = loadProject(sample, sampleOptions());
        EXPECT_EQ(serialiseProject(project), testing::readText(sample))
            << "not canonical: run ctproj-canonicalise on it";
        // Saved into a temporary folder (never into the source tree): relative scene paths stay
        // inside it lexically, so they are still valid there.
        const fs::path copy = folder / sample.filename().string();
        saveProject(project, copy, sampleOptions());
        EXPECT_EQ(testing::readText(copy), testing::readText(sample));
        const Project reloaded = loadProject(copy, sampleOptions());
        EXPECT_EQ(reloaded, project);
    }
}

TEST(Samples, ContentsMatchWhatTheyPromise)
{
    const Project single = loadProject(samplesFolder() / "single-hose.ctproj");
    ASSERT_EQ(single.hoses.size(), 1u);
    EXPECT_TRUE(single.scenes.empty());
    EXPECT_EQ(single.hoses[0].segmentCount, 12);
    EXPECT_EQ(single.hoses[0].route.size(), 2u) << "a straight hose";

    const Project engine = loadProject(samplesFolder() / "engine.ctproj", sampleOptions());
    ASSERT_EQ(engine.scenes.size(), 1u);
    EXPECT_EQ(engine.scenes[0].path, "scenes:2CylinderEngine.glb");
    EXPECT_GE(engine.hoses.size(), 5u);
    EXPECT_EQ(loadProject(samplesFolder() / "engine-50-hoses.ctproj", sampleOptions()).hoses.size(),
              50u);

    const Project rig = loadProject(samplesFolder() / "test-rig.ctproj");
    ASSERT_EQ(rig.scenes.size(), 1u);
    EXPECT_TRUE(
        fs::exists(resolveScenePath(rig.scenes[0], samplesFolder() / "test-rig.ctproj", {})))
        << "the test rig's scene is committed with the sample";

    const Project motionRig = loadProject(samplesFolder() / "motion-rig.ctproj");
    ASSERT_EQ(motionRig.motions.size(), 2u);
    EXPECT_EQ(motionRig.motions[0].kind, PartMotion::Kind::Hinge);
    EXPECT_EQ(motionRig.motions[1].kind, PartMotion::Kind::Slider);
    EXPECT_TRUE(fs::exists(
        resolveScenePath(motionRig.scenes[0], samplesFolder() / "motion-rig.ctproj", {})));
}

TEST(Samples, EngineSceneNeedsTheNamedRootToResolve)
{
    const Project engine = loadProject(samplesFolder() / "engine.ctproj");
    EXPECT_THROW(resolveScenePath(engine.scenes[0], samplesFolder() / "engine.ctproj", {}),
                 PathError);
}

} // namespace
} // namespace chaintube::formats
