// The `chaintube` command-line tool: parse, call the library, print errors, return non-zero.
#include "demo.h"

#include <chaintube/types.h>

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv)
{
    CLI::App app{"chaintube — deformable hoses and cables for VR training scenes"};
    app.require_subcommand(1);
    app.add_subcommand("demo", "Build and deform the built-in sample hoses and print what happened");
    CLI11_PARSE(app, argc, argv);
    try {
        if (app.got_subcommand("demo")) return chaintube::cli::runDemo(std::cout);
    } catch (const chaintube::Error& error) {
        std::cerr << "chaintube: " << error.what() << "\n";
        return 1;
    }
    return 0;
}
