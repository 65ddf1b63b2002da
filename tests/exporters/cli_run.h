// Runs the real `chaintube` CLI (CHAINTUBE_CLI, set by CMake) and captures what it prints.
#pragma once

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace chaintube::exporting::testing {

struct CliRun
{
    int exitCode = -1;
    std::string output; ///< stdout and stderr together
};

inline CliRun runCli(const std::string& arguments)
{
    CliRun run;
    const std::string command = std::string("\"") + CHAINTUBE_CLI + "\" " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    std::array<char, 4096> buffer{};
    size_t got = 0;
    while ((got = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
        run.output.append(buffer.data(), got);
    const int status = pclose(pipe);
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

} // namespace chaintube::exporting::testing
