// The `chaintube` command-line tool: parse, call the library, print errors, return non-zero.
#include "check.h"
#include "commands.h"
#include "demo.h"

#include <CLI/CLI.hpp>
#include <iostream>

int main(int argc, char** argv)
{
    using namespace chaintube::cli;
    CLI::App app{"chaintube — deformable hoses and cables for VR training scenes"};
    app.require_subcommand(1);
    app.add_subcommand("demo",
                       "Build and deform the built-in sample hoses and print what happened");
    ExportCommand exportCommand;
    FileCommand validateCommand, infoCommand;
    addCommands(app, exportCommand, validateCommand, infoCommand);
    CheckCommand checkCommand;
    addCheckCommand(app, checkCommand);
    ReportCommand reportCommand;
    addReportCommand(app, reportCommand);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        return app.exit(error) == 0 ? kExitOk : kExitUsage; // --help prints and exits 0
    }
    try {
        if (app.got_subcommand("demo")) return runDemo(std::cout);
        if (app.got_subcommand("export")) return runExport(exportCommand, std::cout, std::cerr);
        if (app.got_subcommand("validate"))
            return runValidate(validateCommand, std::cout, std::cerr);
        if (app.got_subcommand("info")) return runInfo(infoCommand, std::cout, std::cerr);
        if (app.got_subcommand("check")) return runCheck(checkCommand, std::cout, std::cerr);
        if (app.got_subcommand("report")) return runReport(reportCommand, std::cout, std::cerr);
    } catch (const std::exception& error) {
        std::cerr << "chaintube: " << error.what() << "\n";
        return kExitFailed;
    }
    return kExitOk;
}
