// Shared helpers of the editor tests.
#pragma once

#include "chaintube/editor/document.h"

#include <filesystem>
#include <string>

namespace chaintube::editor::test {

/// Folder of the repository's samples (samples/).
inline std::filesystem::path samplesDir() { return CHAINTUBE_SAMPLES_DIR; }
/// Folder of the third-party scenes; may not exist.
inline std::filesystem::path scenesDir() { return CHAINTUBE_SCENES_DIR; }
inline bool haveScenes() { return std::filesystem::exists(scenesDir() / "2CylinderEngine.glb"); }
inline formats::NamedRoots roots() { return {{"scenes", scenesDir()}}; }
/// Folder for files the tests write (created; inside the build tree).
inline std::filesystem::path outputDir()
{
    const std::filesystem::path dir = CHAINTUBE_TEST_OUTPUT_DIR;
    std::filesystem::create_directories(dir);
    return dir;
}

} // namespace chaintube::editor::test
