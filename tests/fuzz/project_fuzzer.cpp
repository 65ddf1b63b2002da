// libFuzzer target: the project reader (formats::parseProject). Every malformed document must
// be refused with chaintube::Error (ProjectFormatError, PathError …); any other exception, a
// crash, a sanitizer report, a leak or an allocation beyond libFuzzer's limit is a finding.
#include <chaintube/formats/project.h>
#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    chaintube::formats::ProjectLoadOptions options;
    options.roots["scenes"] = "/nonexistent/scenes";
    try {
        const chaintube::formats::Project project =
            chaintube::formats::parseProject(text, "/nonexistent/fuzz/project.ctproj", options);
        // What was accepted must serialise and read back to the same project.
        const std::string canonical = chaintube::formats::serialiseProject(project);
        if (chaintube::formats::parseProject(canonical, "/nonexistent/fuzz/project.ctproj",
                                             options) != project)
            __builtin_trap();
    } catch (const chaintube::Error&) {
    }
    return 0;
}
