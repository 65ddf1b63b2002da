// chaintube-bench-realtime: the 50-hose engine sample run as a VR platform runs it — exported
// to a GLB hose rig, loaded by the runtime (rig::HoseRuntime), every hose's middle point grabbed
// on its own random walk each frame, then HoseRuntime::update().
#pragma once

#include "cases.h"

#include <filesystem>
#include <string>

namespace chaintube::bench::realtime {

struct EngineResult
{
    bool ran = false;
    std::string skipped; ///< why it did not run (scene absent, built without the exporter)
    Row row;
    int hoses = 0;        ///< hoses in the rig
    int grabbedHoses = 0; ///< hoses with a grabbable point (the others are static)
    int gravityHoses = 0; ///< hoses with per-frame gravity (stepped by update())
    int colliders = 0;    ///< collider objects in the rig
    Violation loaded;     ///< largest violation over the hoses as loaded (own measure)
};

/// Exports samplesDir/engine-50-hoses.ctproj (its scene from scenesDir) into workDir (removed
/// afterwards), loads it into a runtime for `warmup` frames (discarded), then into a fresh one
/// for `frames` timed frames. Skips when scenesDir/2CylinderEngine.glb is absent.
EngineResult runEngine(const std::filesystem::path& scenesDir,
                       const std::filesystem::path& samplesDir,
                       const std::filesystem::path& workDir, int frames, int warmup);

} // namespace chaintube::bench::realtime
