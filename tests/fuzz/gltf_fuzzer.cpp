// libFuzzer target: our GLB/glTF container reader and what sits on it — the runtime's loader
// (rig::HoseRuntime::load) and `chaintube validate` (exporting::validateFile). The input is
// written to a .glb file in a private folder (a .gltf when it starts with '{').
// HoseRuntime::load must refuse bad files with chaintube::Error; validateFile must never throw.
#include "fuzz_support.h"

#include <chaintube/export/inspect.h>
#include <chaintube/export/runtime.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const bool text = size > 0 && data[0] == '{';
    const std::filesystem::path file =
        chaintube::fuzz::writeInput(text ? "fuzz.gltf" : "fuzz.glb", data, size);
    try {
        chaintube::rig::HoseRuntime runtime = chaintube::rig::HoseRuntime::load(file);
        runtime.update();
    } catch (const chaintube::Error&) {
    }
    static_cast<void>(chaintube::exporting::validateFile(file, {}));
    return 0;
}
