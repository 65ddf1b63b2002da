// chaintube-scene-reader: reads one scene file with assimp for formats::importScene, in a
// process of its own (see "Process isolation" in scene_import.h). Its only argument of its own
// is the file's extension (".ply"): the format, as importScene decided it.
#include "import_internal.h"

#include <stdexcept>

int main(int argc, char** argv)
{
    using namespace chaintube::formats;
    detail::serveAsReaderProgram(
        argc, argv,
        [](const std::vector<std::string>& arguments, const std::filesystem::path& file,
           const ImportOptions& options, detail::ProgressStage& progress) {
            if (arguments.size() != 1)
                throw std::invalid_argument("expected one argument of its own, the extension");
            return detail::importWithAssimp(file, arguments[0], options, progress);
        });
}
