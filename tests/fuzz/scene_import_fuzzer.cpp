// libFuzzer target: the scene-import wrapper (formats::importScene) on a temporary file. The
// first byte picks the format among a few text/binary ones assimp reads (OBJ, STL, OFF, PLY),
// the rest is the file. Bad files must be refused with chaintube::Error. PLY headers without
// `end_header` made assimp 5.2.5 loop forever (tests/fuzz/findings/assimp-ply-hang.bin); the
// wrapper now refuses them first (test SceneImportHardening.*). Crashes inside assimp itself
// are third-party findings (Debian's libassimp is not instrumented).
#include "fuzz_support.h"

#include <chaintube/formats/scene_import.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size < 1) return 0;
    static const char* const extensions[] = {".obj", ".stl", ".off", ".ply"};
    const std::string name = std::string("fuzz") + extensions[data[0] % 4];
    const std::filesystem::path file = chaintube::fuzz::writeInput(name, data + 1, size - 1);
    try {
        (void)chaintube::formats::importScene(file);
    } catch (const chaintube::Error&) {
    }
    return 0;
}
