// Batch export goes on past broken projects; validate and info judge every kind of file.
#include "export_test_support.h"

#include <chaintube/export/batch.h>
#include <chaintube/export/inspect.h>
#include <chaintube/export/rig_descriptor.h>
#include <mutex>
#include <sstream>

namespace chaintube::exporting::testing {
namespace {

bool anyContains(const std::vector<std::string>& messages, const std::string& part)
{
    for (const std::string& message : messages)
        if (message.find(part) != std::string::npos) return true;
    return false;
}

TEST(BatchExport, ContinuesPastABrokenProjectAndReportsEveryFailure)
{
    TemporaryFolder folder;
    fs::create_directories(folder / "projects/scenes");
    for (const char* sample : {"single-hose", "test-rig"})
        fs::copy_file(samplesDir() / (std::string(sample) + ".ctproj"),
                      folder / "projects" / (std::string(sample) + ".ctproj"));
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "projects/scenes/test-rig.gltf");
    writeBytes(folder / "projects/broken.ctproj", "{ \"format\": \"chaintube-project\", ");
    writeBytes(folder / "projects/missing-scene.ctproj",
               readBytes(samplesDir() / "engine.ctproj")); // names root "scenes", not given

    const std::vector<fs::path> projects = findProjects((folder / "projects").string());
    ASSERT_EQ(projects.size(), 4u);
    std::vector<BatchEvent> events;
    std::mutex guard;
    const BatchResult result =
        exportBatch(projects, folder / "out", {}, 2, [&](const BatchEvent& e) {
            const std::lock_guard<std::mutex> lock(guard);
            events.push_back(e);
        });
    EXPECT_EQ(result.exported.size(), 2u);
    ASSERT_EQ(result.failures.size(), 2u);
    EXPECT_EQ(result.failures[0].project.filename(), "broken.ctproj");
    EXPECT_NE(result.failures[0].message.find("broken.ctproj"), std::string::npos);
    EXPECT_EQ(result.failures[1].project.filename(), "missing-scene.ctproj");
    EXPECT_NE(result.failures[1].message.find("scenes"), std::string::npos)
        << result.failures[1].message;
    EXPECT_EQ(events.size(), 4u);
    EXPECT_EQ(events.back().finished, 4);
    EXPECT_TRUE(fs::exists(folder / "out/single-hose.glb"));
    EXPECT_TRUE(fs::exists(folder / "out/test-rig.hoses.json"));
    EXPECT_FALSE(fs::exists(folder / "out/broken.glb"));
}

TEST(BatchExport, AGlobPatternSelectsProjectsAndSameNamedProjectsDoNotOverwriteEachOther)
{
    TemporaryFolder folder;
    fs::create_directories(folder / "a");
    fs::create_directories(folder / "b");
    fs::copy_file(samplesDir() / "single-hose.ctproj", folder / "a/hose.ctproj");
    fs::copy_file(samplesDir() / "single-hose.ctproj", folder / "b/hose.ctproj");
    const std::vector<fs::path> projects = findProjects((folder / "*/hose.ctproj").string());
    ASSERT_EQ(projects.size(), 2u);
    const BatchResult result = exportBatch(projects, folder / "out", {}, 2);
    EXPECT_EQ(result.exported.size(), 1u);
    ASSERT_EQ(result.failures.size(), 1u);
    EXPECT_NE(result.failures[0].message.find("already written"), std::string::npos);
    EXPECT_TRUE(findProjects((folder / "nothing-*.ctproj").string()).empty());
}

TEST(ValidateFile, AcceptsEveryExportedSampleAndItsDescriptor)
{
    TemporaryFolder folder;
    for (const std::string& sample : availableSamples()) {
        exportProjectFile(samplesDir() / (sample + ".ctproj"), folder / (sample + ".glb"), roots());
        for (const fs::path& file : {folder / (sample + ".glb"), folder / (sample + ".hoses.json"),
                                     samplesDir() / (sample + ".ctproj")}) {
            const ValidationResult result = validateFile(file, roots());
            EXPECT_TRUE(result.valid()) << file << ": " << result.errors.front();
        }
    }
}

TEST(ValidateFile, RejectsAnExportWhoseExtensionIsRequired)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "test-rig.ctproj", folder / "rig.gltf", roots());
    Json gltf = Json::parse(readBytes(folder / "rig.gltf"));
    gltf["extensionsRequired"] = Json::array({rig::kExtensionName});
    writeBytes(folder / "rig.gltf", gltf.dump());
    const ValidationResult result = validateFile(folder / "rig.gltf", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "/extensionsRequired"));
}

TEST(ValidateFile, RejectsJointsThatDoNotSitOnTheirRings)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "single-hose.ctproj", folder / "hose.gltf", roots());
    Json gltf = Json::parse(readBytes(folder / "hose.gltf"));
    const int joint = gltf["extensions"][rig::kExtensionName]["hoses"][0]["joints"][3].get<int>();
    gltf["nodes"][static_cast<size_t>(joint)]["translation"][1] = 7.0;
    writeBytes(folder / "hose.gltf", gltf.dump());
    const ValidationResult result = validateFile(folder / "hose.gltf", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "/hoses/0/joints/3")) << result.errors.front();
}

TEST(ValidateFile, RejectsADescriptorWhosePerJointLimitsContradictItsMaterial)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "single-hose.ctproj", folder / "hose.glb", roots());
    Json descriptor = Json::parse(readBytes(folder / "hose.hoses.json"));
    descriptor["hoses"][0]["jointBendLimits"][2] = 0.1;
    writeBytes(folder / "edited.hoses.json", descriptor.dump());
    const ValidationResult result = validateFile(folder / "edited.hoses.json", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "edited.hoses.json: /hoses/0/jointBendLimits/2"))
        << result.errors.front();
}

TEST(ValidateFile, NeverReadsABufferOutsideTheGltfsFolder)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "single-hose.ctproj", folder / "hose.gltf", roots());
    Json gltf = Json::parse(readBytes(folder / "hose.gltf"));
    gltf["buffers"][0]["uri"] = "../../../../etc/hostname";
    writeBytes(folder / "hose.gltf", gltf.dump());
    const ValidationResult result = validateFile(folder / "hose.gltf", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "/buffers/0/uri")) << result.errors.front();
}

TEST(ValidateFile, ReportsAnAccessorReachingBeyondItsBuffer)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "single-hose.ctproj", folder / "hose.gltf", roots());
    Json gltf = Json::parse(readBytes(folder / "hose.gltf"));
    const int skin = gltf["extensions"][rig::kExtensionName]["hoses"][0]["skin"].get<int>();
    const size_t inverseBind =
        gltf["skins"][static_cast<size_t>(skin)]["inverseBindMatrices"].get<size_t>();
    gltf["accessors"][inverseBind]["count"] = 1u << 30;
    writeBytes(folder / "hose.gltf", gltf.dump());
    const ValidationResult result = validateFile(folder / "hose.gltf", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "reaches beyond its buffer")) << result.errors.front();
}

TEST(ValidateFile, ReportsAProjectWhoseScenesCannotBeFound)
{
    const ValidationResult result = validateFile(samplesDir() / "engine.ctproj", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "engine.ctproj"));
}

TEST(ValidateFile, NamesTheFileThatCannotBeRead)
{
    const ValidationResult result = validateFile("/nonexistent/x.glb", {});
    EXPECT_FALSE(result.valid());
    EXPECT_TRUE(anyContains(result.errors, "/nonexistent/x.glb"));
}

TEST(DescribeFile, ListsHosesLengthsMaterialsAttachmentsAndWarnings)
{
    TemporaryFolder folder;
    exportProjectFile(samplesDir() / "test-rig.ctproj", folder / "rig.glb", roots());
    for (const fs::path& file :
         {folder / "rig.glb", folder / "rig.hoses.json", samplesDir() / "test-rig.ctproj"}) {
        std::ostringstream out;
        const int warnings = describeFile(file, roots(), out);
        const std::string text = out.str();
        EXPECT_NE(text.find("hose 'left-feed'"), std::string::npos) << text;
        EXPECT_NE(text.find("rest length"), std::string::npos);
        EXPECT_NE(text.find("minimum bend radius 0.12 m"), std::string::npos) << text;
        if (file.extension() != ".json") { // a descriptor alone has node indices, not names
            EXPECT_NE(text.find("bracket_left"), std::string::npos) << text;
        }
        // The sample's routes bend within their materials' limits.
        EXPECT_EQ(warnings, 0) << text;
        EXPECT_EQ(text.find("below the minimum bend radius"), std::string::npos) << text;
    }
    // A route with a corner too tight for its legs is reported.
    formats::Project tight = formats::loadProject(samplesDir() / "test-rig.ctproj");
    tight.hoses[0].route = {Vec3(-0.3, 0.21, 0.0), Vec3(-0.3, 0.26, 0.0), Vec3(-0.2, 0.26, 0.0),
                            Vec3(0.0283, 0.04, 0.1217)};
    fs::create_directories(folder / "scenes");
    fs::copy_file(samplesDir() / "scenes/test-rig.gltf", folder / "scenes/test-rig.gltf");
    formats::saveProject(tight, folder / "tight.ctproj");
    std::ostringstream out;
    EXPECT_GT(describeFile(folder / "tight.ctproj", roots(), out), 0) << out.str();
    EXPECT_NE(out.str().find("below the minimum bend radius"), std::string::npos) << out.str();
}

} // namespace
} // namespace chaintube::exporting::testing
