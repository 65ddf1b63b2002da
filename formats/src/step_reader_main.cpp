// chaintube-step-reader: reads one STEP file with OpenCASCADE for formats::importScene, in a
// process of its own (see "Process isolation" in scene_import.h). No arguments of its own.
#include "import_internal.h"

#include <stdexcept>

int main(int argc, char** argv)
{
    using namespace chaintube::formats;
    detail::serveAsReaderProgram(
        argc, argv,
        [](const std::vector<std::string>& arguments, const std::filesystem::path& file,
           const ImportOptions& options, detail::ProgressStage& progress) {
            if (!arguments.empty()) throw std::invalid_argument("expected no arguments of its own");
            return detail::importStep(file, options, progress);
        });
}
