// libFuzzer target: the scene-import wrapper (formats::importScene) on a temporary file. The
// first byte picks the format among a few text/binary ones assimp reads (OBJ, STL, OFF, PLY),
// the rest is the file. Bad files must be refused with chaintube::Error.
//
// importScene runs assimp in a reader program of its own (chaintube-scene-reader, built with the
// same sanitizers; scene_import.h, "Process isolation"), so an assimp crash — the ai_assert
// abort in TriangulateProcess on a PLY face without indices,
// tests/fuzz/findings/assimp-ply-triangulate-abort.bin — is an ImportError here, as for a user,
// and the run goes on. What the wrapper does before and after the reader (the PLY/OFF header
// checks, decoding the reader's answer, finaliseScene) runs in this process and is instrumented
// as before; the reader's coverage does not reach libFuzzer. A reader that exits non-zero
// without a signal hit a sanitizer report in our conversion code (or an allocation over
// build.sh's max_allocation_size_mb): that is
// our bug, so its report is printed and the run stops. PLY headers without `end_header` made
// assimp 5.2.5 loop forever (tests/fuzz/findings/assimp-ply-hang.bin), and an element name
// starting with digits made it read them as the count and ask for 21 GB
// (tests/fuzz/findings/assimp-ply-element-name-digits-21gb.bin, also in the corpus); the wrapper
// refuses both first (test SceneImportHardening.*).
#include "fuzz_support.h"

#include <chaintube/formats/scene_import.h>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

/// Inputs whose importer process died, by signal: printed when the run ends, so a run says how
/// often the isolation was needed. (A plain array: it must outlive the atexit handler.)
long crashesBySignal[NSIG] = {};

void printCrashes()
{
    long total = 0;
    for (const long count : crashesBySignal)
        total += count;
    std::fprintf(stderr, "scene_import_fuzzer: %ld inputs crashed the importer process", total);
    const char* separator = ":";
    for (int signal = 1; signal < NSIG; ++signal) {
        if (crashesBySignal[signal] == 0) continue;
        const char* name = ::sigabbrev_np(signal);
        std::fprintf(stderr, "%s SIG%s %ld", separator, name ? name : "?", crashesBySignal[signal]);
        separator = ",";
    }
    std::fprintf(stderr, "\n");
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    std::atexit(printCrashes);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size < 1) return 0;
    static const char* const extensions[] = {".obj", ".stl", ".off", ".ply"};
    const std::string name = std::string("fuzz") + extensions[data[0] % 4];
    const std::filesystem::path file = chaintube::fuzz::writeInput(name, data + 1, size - 1);
    try {
        static_cast<void>(chaintube::formats::importScene(file));
    } catch (const chaintube::formats::ImportError& error) {
        if (error.signal() == 0) {
            std::fprintf(stderr, "scene_import_fuzzer: %s\n--- the importer process wrote:\n%s\n",
                         error.what(), error.readerOutput().c_str());
            std::abort();
        }
        if (error.signal() > 0 && error.signal() < NSIG) ++crashesBySignal[error.signal()];
    } catch (const chaintube::Error&) {
    }
    return 0;
}
