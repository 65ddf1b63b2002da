// libFuzzer target: the scene-import wrapper (formats::importScene) on a temporary file. The
// first byte picks the format among a few text/binary ones assimp reads (OBJ, STL, OFF), the
// rest is the file. PLY is left out: assimp 5.2.5 hangs on a 100-byte PLY
// (tests/fuzz/findings/assimp-ply-hang.bin, a third-party finding not fixed here). Bad files must be refused with chaintube::Error. Crashes inside
// assimp itself are third-party findings (Debian's libassimp is not instrumented).
#include "fuzz_support.h"

#include <chaintube/formats/scene_import.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size < 1) return 0;
    static const char* const extensions[] = {".obj", ".stl", ".off"};
    const std::string name = std::string("fuzz") + extensions[data[0] % 3];
    const std::filesystem::path file = chaintube::fuzz::writeInput(name, data + 1, size - 1);
    try {
        (void)chaintube::formats::importScene(file);
    } catch (const chaintube::Error&) {
    }
    return 0;
}
