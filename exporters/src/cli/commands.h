// The `chaintube` subcommands other than demo: export, validate, info. Each is a function over
// already-parsed options that returns the process exit code (see kExit*), so main() only parses.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace chaintube::cli {

/// Exit codes of every subcommand (documented in exporters/README.md and in --help).
constexpr int kExitOk = 0; ///< done; for validate: the file is valid
constexpr int kExitFailed =
    1; ///< the work failed: invalid file, export error, a batch project failed
constexpr int kExitUsage = 2; ///< bad command line (unknown option, missing argument)

struct ExportCommand
{
    std::string project;            ///< a project file (single export)
    std::vector<std::string> batch; ///< folders, glob patterns or files of projects (batch export)
    std::string output;             ///< OUT.glb | OUT.gltf, or the batch output folder
    std::vector<std::string> roots; ///< NAME=DIR
    std::string format = "glb";     ///< batch: glb | gltf
    int jobs = 2;
    bool quiet = false;
    bool jointsAtRoot = false; ///< ExportOptions::jointsUnderAttachedNodes = false
    bool textureCoordinates = false;
    std::string report; ///< --report csv|json|md: a length report beside each export ("": none)
};

/// `chaintube report PROJECT_OR_FOLDER --format csv|json|md [-o FILE]`.
struct ReportCommand
{
    std::string source; ///< a project file or a folder of them
    std::string format = "csv";
    std::string output; ///< "": stdout
    std::vector<std::string> roots;
    int steps = 20;
    double clearance = 0.0;
    bool noFit = false;
    bool quiet = false;
};

struct FileCommand
{
    std::string file;
    std::vector<std::string> roots;
};

/// Registers export, validate and info on `app`; their options are written into the structs.
void addCommands(CLI::App& app, ExportCommand& exportCommand, FileCommand& validateCommand,
                 FileCommand& infoCommand);

/// Registers `report` on `app`.
void addReportCommand(CLI::App& app, ReportCommand& command);

int runExport(const ExportCommand& command, std::ostream& out, std::ostream& err);
int runReport(const ReportCommand& command, std::ostream& out, std::ostream& err);
int runValidate(const FileCommand& command, std::ostream& out, std::ostream& err);
int runInfo(const FileCommand& command, std::ostream& out, std::ostream& err);

} // namespace chaintube::cli
