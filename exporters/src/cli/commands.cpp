#include "commands.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chaintube/export/batch.h>
#include <chaintube/export/gltf_export.h>
#include <chaintube/export/inspect.h>
#include <chaintube/export/report.h>
#include <chaintube/formats/atomic_file.h>
#include <chaintube/formats/errors.h>
#include <filesystem>
#include <iomanip>

namespace chaintube::cli {

namespace {

const char* kExitCodes =
    "Exit codes: 0 success (validate: the file is valid), 1 the work failed "
    "(invalid file, export error, any batch project failed), 2 bad command line.";

formats::NamedRoots parseRoots(const std::vector<std::string>& roots)
{
    formats::NamedRoots result;
    for (const std::string& root : roots) {
        const size_t equals = root.find('=');
        if (equals == std::string::npos || equals == 0 || equals + 1 == root.size())
            throw InvalidArgument("--root '" + root +
                                  "': expected NAME=DIR, e.g. scenes=../shared/scenes");
        result[root.substr(0, equals)] = root.substr(equals + 1);
    }
    return result;
}

void addRootOption(CLI::App& command, std::vector<std::string>& roots)
{
    command.add_option("--root", roots,
                       "Named root for project paths \"NAME:path\", as NAME=DIR (repeatable), "
                       "e.g. --root scenes=../shared/scenes");
}

exporting::ExportOptions exportOptionsOf(const ExportCommand& command)
{
    exporting::ExportOptions options;
    options.jointsUnderAttachedNodes = !command.jointsAtRoot;
    options.writeTextureCoordinates = command.textureCoordinates;
    return options;
}

/// Writes the length report of `project` beside its export `gltfFile`:
/// <name>.report.<csv|json|md>. Returns the file written.
std::filesystem::path writeReportBeside(const std::filesystem::path& project,
                                        const std::filesystem::path& gltfFile,
                                        const formats::NamedRoots& roots,
                                        exporting::ReportFormat format)
{
    std::filesystem::path file = gltfFile;
    file.replace_extension(std::string(".report.") + exporting::extensionOf(format));
    const exporting::LengthReport report = exporting::reportProjects({project}, roots);
    formats::writeFileAtomically(file, exporting::formatReport(report, format));
    return file;
}

} // namespace

void addCommands(CLI::App& app, ExportCommand& exportCommand, FileCommand& validateCommand,
                 FileCommand& infoCommand)
{
    CLI::App* exporter = app.add_subcommand(
        "export", "Export a project (or a batch of projects) to a glTF hose rig with its runtime "
                  "descriptor (<name>.hoses.json beside it)");
    exporter->footer(
        std::string("Examples:\n  chaintube export samples/test-rig.ctproj -o rig.glb\n"
                    "  chaintube export --batch 'samples/*.ctproj' -o out/ -j 2 --root "
                    "scenes=../shared/scenes\n") +
        kExitCodes);
    exporter->add_option("project", exportCommand.project, "Project file (*.ctproj)");
    exporter->add_option("--batch", exportCommand.batch,
                         "Export every project in a folder, or matching a glob pattern (several "
                         "folders, patterns or project files may follow)");
    exporter->add_option("-o,--output", exportCommand.output,
                         "OUT.glb or OUT.gltf (+ OUT.bin); with --batch the output folder. "
                         "Default: the project's export settings, else <project>.glb beside it");
    exporter->add_option("-j,--jobs", exportCommand.jobs, "Batch: projects exported in parallel")
        ->check(CLI::Range(1, 64));
    exporter->add_option("--format", exportCommand.format, "Batch: glb or gltf")
        ->check(CLI::IsMember({"glb", "gltf"}));
    exporter->add_flag("-q,--quiet", exportCommand.quiet, "No progress on stderr");
    exporter->add_flag("--joints-at-root", exportCommand.jointsAtRoot,
                       "Put every hose's joints under its own root node instead of under the scene "
                       "nodes it is attached to (Blender then makes one armature per hose; moving "
                       "a scene node in a plain viewer no longer carries the hose)");
    exporter->add_flag("--uvs", exportCommand.textureCoordinates,
                       "Write the hoses' texture coordinates (TEXCOORD_0)");
    exporter
        ->add_option("--report", exportCommand.report,
                     "Also write each project's length and bill-of-materials report beside its "
                     "export, <name>.report.csv|json|md (as `chaintube report`)")
        ->check(CLI::IsMember({"csv", "json", "md"}));
    addRootOption(*exporter, exportCommand.roots);

    CLI::App* validate = app.add_subcommand(
        "validate", "Check a project, a hose-rig descriptor or an exported glTF/GLB: schema and "
                    "hose invariants. Exit 0 only when valid");
    validate->footer(kExitCodes);
    validate->add_option("file", validateCommand.file, "*.ctproj, *.hoses.json, *.glb or *.gltf")
        ->required();
    addRootOption(*validate, validateCommand.roots);

    CLI::App* info = app.add_subcommand(
        "info", "Describe the hoses of a project, descriptor or export: lengths, materials, "
                "attachments, gravity (on/off, direction), torsion (on/off, twist limit per "
                "joint), the collider objects, and warnings (overstretch, bend below minimum, "
                "self-intersection)");
    info->footer(kExitCodes);
    info->add_option("file", infoCommand.file, "*.ctproj, *.hoses.json, *.glb or *.gltf")
        ->required();
    addRootOption(*info, infoCommand.roots);
}

int runExport(const ExportCommand& command, std::ostream& out, std::ostream& err)
{
    const formats::NamedRoots roots = parseRoots(command.roots);
    if (command.batch.empty() == command.project.empty()) {
        err << "chaintube export: give either a PROJECT or --batch DIR_OR_GLOB\n";
        return kExitUsage;
    }
    if (!command.batch.empty()) {
        if (command.output.empty()) {
            err << "chaintube export --batch: -o OUTDIR is required\n";
            return kExitUsage;
        }
        std::vector<std::filesystem::path> projects;
        for (const std::string& argument : command.batch) {
            const auto found = exporting::findProjects(argument);
            if (found.empty()) {
                err << "chaintube export --batch: no *.ctproj matches '" << argument << "'\n";
                return kExitFailed;
            }
            projects.insert(projects.end(), found.begin(), found.end());
        }
        exporting::ExportOptions options = exportOptionsOf(command);
        options.container =
            command.format == "gltf" ? exporting::Container::Gltf : exporting::Container::Glb;
        std::vector<std::pair<std::filesystem::path, std::filesystem::path>> exported;
        const exporting::BatchResult result = exporting::exportBatch(
            projects, command.output, roots, command.jobs,
            [&](const exporting::BatchEvent& event) {
                if (event.ok) exported.emplace_back(event.project, event.report->gltfFile);
                if (command.quiet && event.ok) return;
                err << "[" << event.finished << "/" << event.total << "] "
                    << (event.ok ? "ok     " : "FAILED ") << event.message << "\n";
                if (event.ok && !event.report->warnings.empty())
                    err << "        " << event.report->warnings.size()
                        << " warning(s) about the hoses' state: chaintube info "
                        << event.report->gltfFile.string() << " lists them\n";
            },
            options);
        out << "exported " << result.exported.size() << " of " << projects.size()
            << " project(s) to " << command.output << " in " << std::fixed << std::setprecision(2)
            << result.seconds << " s\n"
            << std::defaultfloat;
        for (const exporting::BatchFailure& failure : result.failures)
            out << "failed: " << failure.message << "\n";
        if (!command.report.empty()) {
            std::sort(exported.begin(), exported.end());
            for (const auto& [project, gltfFile] : exported)
                out << "wrote "
                    << writeReportBeside(project, gltfFile, roots,
                                         exporting::reportFormatFromName(command.report))
                           .string()
                    << "\n";
        }
        return result.ok() ? kExitOk : kExitFailed;
    }
    exporting::ExportOptions options = exportOptionsOf(command);
    int lastPercent = -1;
    if (!command.quiet)
        options.progress = [&](double fraction) {
            const int percent = static_cast<int>(fraction * 100.0);
            if (percent / 10 != lastPercent / 10) err << "  " << percent << " %\n";
            lastPercent = percent;
            return true;
        };
    if (!command.output.empty() && std::filesystem::path(command.output).has_parent_path())
        std::filesystem::create_directories(std::filesystem::path(command.output).parent_path());
    const exporting::ExportReport report =
        exporting::exportProjectFile(command.project, command.output, roots, options);
    for (const std::string& warning : report.warnings)
        err << "warning: " << warning << "\n";
    out << "wrote " << report.gltfFile.string();
    if (!report.binFile.empty()) out << " + " << report.binFile.filename().string();
    if (!report.descriptorFile.empty()) out << " + " << report.descriptorFile.filename().string();
    out << ": " << report.hoseCount << " hoses, " << report.jointCount << " joints, "
        << report.sceneNodeCount << " scene nodes, " << report.bytesWritten / 1024 << " KiB in "
        << std::fixed << std::setprecision(3) << report.seconds << " s\n"
        << std::defaultfloat;
    if (!command.report.empty())
        out << "wrote "
            << writeReportBeside(command.project, report.gltfFile, roots,
                                 exporting::reportFormatFromName(command.report))
                   .string()
            << "\n";
    return kExitOk;
}

void addReportCommand(CLI::App& app, ReportCommand& command)
{
    CLI::App* report = app.add_subcommand(
        "report", "The length and bill-of-materials report of a project or of every project in a "
                  "folder: per hose its material, cut length (rest length + fittings allowance), "
                  "slack over the shortest valid length (as check --fit-length finds it, for "
                  "hoses between fixed ends), smallest bend radius against the limit, smallest "
                  "clearance to a scene object over the motions (as check --sweep), attachments "
                  "and clips; then the totals per material");
    report->footer(std::string("Examples:\n  chaintube report samples/test-rig.ctproj --format md\n"
                               "  chaintube report samples --format csv -o bom.csv --root "
                               "scenes=../shared/scenes\n"
                               "Lengths in metres. Columns: exporters/README.md, \"Length and "
                               "bill-of-materials reports\".\n") +
                   kExitCodes);
    report->add_option("source", command.source, "A project file (*.ctproj) or a folder of them")
        ->required();
    report->add_option("--format", command.format, "csv, json or md (default csv)")
        ->check(CLI::IsMember({"csv", "json", "md"}));
    report->add_option("-o,--output", command.output, "Write the report to FILE (default stdout)");
    report->add_option("--steps", command.steps, "Sweep steps each way, 1 ... 100000 (default 20)")
        ->check(CLI::Range(1, 100000));
    report
        ->add_option("--clearance", command.clearance,
                     "Clearance threshold in metres for the length fit (default 0: collisions "
                     "only)")
        ->check(CLI::NonNegativeNumber);
    report->add_flag("--no-fit", command.noFit,
                     "Skip the length fit (no shortest valid length, no slack; much faster)");
    report->add_flag("-q,--quiet", command.quiet, "No progress on stderr");
    addRootOption(*report, command.roots);
}

int runReport(const ReportCommand& command, std::ostream& out, std::ostream& err)
{
    const formats::NamedRoots roots = parseRoots(command.roots);
    const std::vector<std::filesystem::path> projects = exporting::reportSources(command.source);
    exporting::ReportOptions options;
    options.steps = command.steps;
    options.clearanceThreshold = command.clearance;
    options.fitLength = !command.noFit;
    exporting::LengthReport report;
    for (const std::filesystem::path& project : projects) {
        int lastTenth = -1;
        if (!command.quiet)
            options.progress = [&](double fraction) {
                const int tenth = static_cast<int>(fraction * 10.0);
                if (tenth != lastTenth)
                    err << "  " << project.string() << " " << 10 * tenth << " %\n";
                lastTenth = tenth;
                return true;
            };
        exporting::LengthReport one = exporting::reportProjects({project}, roots, options);
        report.projects.push_back(project.string());
        for (exporting::HoseReport& hose : one.hoses)
            report.hoses.push_back(std::move(hose));
    }
    report.materials = exporting::materialTotals(report.hoses);
    const std::string text =
        exporting::formatReport(report, exporting::reportFormatFromName(command.format));
    if (command.output.empty()) {
        out << text;
    } else {
        formats::writeFileAtomically(command.output, text);
        if (!command.quiet) err << "wrote " << command.output << "\n";
    }
    return kExitOk;
}

int runValidate(const FileCommand& command, std::ostream& out, std::ostream& err)
{
    const exporting::ValidationResult result =
        exporting::validateFile(command.file, parseRoots(command.roots));
    for (const std::string& error : result.errors)
        err << "error: " << error << "\n";
    for (const std::string& warning : result.warnings)
        err << "warning: " << warning << "\n";
    out << command.file << ": " << (result.valid() ? "valid" : "INVALID") << " ("
        << result.errors.size() << " error(s), " << result.warnings.size() << " warning(s))\n";
    return result.valid() ? kExitOk : kExitFailed;
}

int runInfo(const FileCommand& command, std::ostream& out, std::ostream&)
{
    const int warnings = exporting::describeFile(command.file, parseRoots(command.roots), out);
    out << warnings << " warning(s)\n";
    return kExitOk;
}

} // namespace chaintube::cli
