// chaintube-test-reader: a reader program for reader_process_test.cpp that ends in every way a
// third-party reader can (its one argument picks how), run through the same
// serveAsReaderProgram as chaintube-scene-reader.
#include "test_reader_scene.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>
#include <unistd.h>

int main(int argc, char** argv)
{
    using namespace chaintube::formats;
    using namespace chaintube::formats::detail;
    serveAsReaderProgram(argc, argv,
                         [](const std::vector<std::string>& arguments,
                            const std::filesystem::path& file, const ImportOptions& options,
                            ProgressStage& progress) -> ReaderResult {
                             const std::string how = arguments.empty() ? "" : arguments[0];
                             if (how == "crash") {
                                 std::fputs("about to crash\n", stderr);
                                 std::raise(SIGSEGV);
                             } else if (how == "exit-3") {
                                 ::_exit(3);
                             } else if (how == "file-error") {
                                 throw FileError(file, "cannot read PLY file: no faces");
                             } else if (how == "scene") {
                                 return testReaderScene();
                             } else if (how == "options") { // the options, back as numbers
                                 ReaderResult echo = testReaderScene();
                                 echo.metresPerReaderUnit = options.metresPerUnit.value_or(-1.0);
                                 echo.sourceUnitsPerReaderUnit = options.chordalTolerance;
                                 echo.scene.sourceUnits.metresPerUnit = options.angularTolerance;
                                 echo.scene.format = options.upAxis == UpAxis::PositiveZ ? "z"
                                                     : options.upAxis                    ? "y"
                                                                                         : "-";
                                 return echo;
                             } else if (how == "silent") {
                                 progress.report(0.25);
                                 std::this_thread::sleep_for(std::chrono::seconds(60));
                                 return {};
                             }
                             throw std::invalid_argument("unknown test reader '" + how + "'");
                         });
}
