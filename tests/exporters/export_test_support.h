// Helpers for exporter tests: temporary folders, the samples, reading GLB chunks and accessors.
#pragma once

#include "chaintube/test_support/files.h"

#include <chaintube/export/gltf_export.h>
#include <chaintube/formats/project_hoses.h>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace chaintube::exporting::testing {

namespace fs = std::filesystem;
using Json = nlohmann::json;

using test_support::haveScenes;
using test_support::samplesDir;
using test_support::scenesDir;
using test_support::TemporaryFolder;
/// The whole file's bytes.
inline std::string readBytes(const fs::path& file)
{
    return test_support::readText(file);
}
inline void writeBytes(const fs::path& file, const std::string& bytes)
{
    test_support::writeText(file, bytes);
}
/// Test projects of this folder (data/), e.g. rig-options.ctproj (root "samples:").
inline fs::path testDataDir()
{
    return CHAINTUBE_EXPORT_TEST_DATA_DIR;
}
inline formats::NamedRoots roots()
{
    return {{"scenes", scenesDir()}, {"samples", samplesDir()}};
}
/// loadProject() with the test roots ("scenes:", "samples:").
inline formats::Project loadWithRoots(const fs::path& projectFile)
{
    formats::ProjectLoadOptions load;
    load.roots = roots();
    return formats::loadProject(projectFile, load);
}

/// The rig-options sample with gravity on for bracket-loop, exported to `folder`/loop.glb.
inline fs::path exportLoopWithGravity(const TemporaryFolder& folder)
{
    std::ifstream in(testDataDir() / "rig-options.ctproj");
    nlohmann::json project = nlohmann::json::parse(in);
    for (nlohmann::json& hose : project.at("hoses"))
        if (hose.at("id") == "bracket-loop")
            hose["gravity"] = {{"enabled", true}, {"direction", {0.0, -1.0, 0.0}}};
    const fs::path file = folder / "loop.ctproj";
    std::ofstream(file) << project.dump(2);
    const fs::path glb = folder / "loop.glb";
    exportProjectFile(file, glb, roots());
    return glb;
}
/// A sample's project file: samples/<name>.ctproj, or data/<name>.ctproj for the test projects.
inline fs::path projectFileOf(const std::string& name)
{
    const fs::path sample = samplesDir() / (name + ".ctproj");
    return fs::exists(sample) ? sample : testDataDir() / (name + ".ctproj");
}

/// Samples whose scenes are present (the engine samples need ../shared/scenes).
inline std::vector<std::string> availableSamples()
{
    std::vector<std::string> samples{"single-hose", "test-rig"};
    if (haveScenes()) {
        samples.push_back("engine");
        samples.push_back("engine-50-hoses");
    }
    return samples;
}

/// The glTF JSON and buffer 0 of a .glb or .gltf (+ .bin).
struct GltfDocument
{
    Json json;
    std::string bin;
};

inline GltfDocument readGltf(const fs::path& file)
{
    GltfDocument document;
    const std::string bytes = readBytes(file);
    if (bytes.compare(0, 4, "glTF") == 0) {
        std::uint32_t jsonLength = 0, binLength = 0;
        std::memcpy(&jsonLength, bytes.data() + 12, 4);
        document.json = Json::parse(bytes.substr(20, jsonLength));
        if (20 + jsonLength + 8 <= bytes.size()) {
            std::memcpy(&binLength, bytes.data() + 20 + jsonLength, 4);
            document.bin = bytes.substr(20 + jsonLength + 8, binLength);
        }
    } else {
        document.json = Json::parse(bytes);
        if (document.json.contains("buffers"))
            document.bin = readBytes(file.parent_path() /
                                     document.json["buffers"][0]["uri"].get<std::string>());
    }
    return document;
}

/// Float accessor values (tightly packed, as the exporter writes them).
inline std::vector<float> floatAccessor(const GltfDocument& document, int accessorIndex)
{
    const Json& accessor = document.json["accessors"][static_cast<size_t>(accessorIndex)];
    const Json& view = document.json["bufferViews"][accessor["bufferView"].get<size_t>()];
    const std::map<std::string, size_t> components{
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
    const size_t count =
        accessor["count"].get<size_t>() * components.at(accessor["type"].get<std::string>());
    std::vector<float> values(count);
    std::memcpy(values.data(),
                document.bin.data() + view.value("byteOffset", size_t{0}) +
                    accessor.value("byteOffset", size_t{0}),
                count * 4);
    return values;
}

} // namespace chaintube::exporting::testing
