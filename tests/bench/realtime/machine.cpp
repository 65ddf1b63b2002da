#include "machine.h"

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <sched.h>

namespace chaintube::bench::realtime {

namespace {
// The first line a shell command prints, without its newline ("" when it fails).
std::string firstLineOf(const std::string& command)
{
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
    if (!pipe) return "";
    std::array<char, 256> buffer{};
    std::string line;
    if (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()))
        line = buffer.data();
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r'))
        line.pop_back();
    return line;
}

std::string quoted(const std::filesystem::path& path)
{
    std::string text = "'";
    for (char c : path.string())
        text += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return text + "'";
}
} // namespace

std::string gitCommit(const std::filesystem::path& sourceDir)
{
    const std::string git = "git -C " + quoted(sourceDir);
    const std::string commit = firstLineOf(git + " rev-parse --short=12 HEAD 2>/dev/null");
    if (commit.empty()) return "unknown";
    const bool changed =
        !firstLineOf(git + " status --porcelain --untracked-files=no 2>/dev/null").empty();
    return changed ? commit + " (+ local changes)" : commit;
}

std::string cpuModel()
{
    std::ifstream in("/proc/cpuinfo");
    std::string line, name, family, model;
    int processors = 0;
    auto value = [&line] {
        const size_t colon = line.find(':');
        const size_t start = colon == std::string::npos ? std::string::npos
                                                        : line.find_first_not_of(" \t", colon + 1);
        return start == std::string::npos ? std::string() : line.substr(start);
    };
    while (std::getline(in, line)) {
        if (line.rfind("processor", 0) == 0)
            ++processors;
        else if (line.rfind("model name", 0) == 0 && name.empty())
            name = value();
        else if (line.rfind("cpu family", 0) == 0 && family.empty())
            family = value();
        else if (line.rfind("model", 0) == 0 && model.empty())
            model = value();
    }
    if (name.empty()) return "unknown";
    return name + " (family " + family + ", model " + model + "), " + std::to_string(processors) +
           " CPUs";
}

std::string utcDate()
{
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char buffer[64];
    std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M:%S UTC", &utc);
    return buffer;
}

std::string loadAverage()
{
    std::ifstream in("/proc/loadavg");
    std::string oneMinute;
    return (in >> oneMinute) ? oneMinute : std::string("unknown");
}

bool pinToCpu(int cpu, std::string& error)
{
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
        error = "CPU " + std::to_string(cpu) + " out of range";
        return false;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) {
        error = std::strerror(errno);
        return false;
    }
    return true;
}

std::string allowedCpus()
{
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return "unknown";
    std::string text;
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (!CPU_ISSET(cpu, &set)) continue;
        int last = cpu;
        while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set))
            ++last;
        text += (text.empty() ? "" : ",") + std::to_string(cpu) +
                (last > cpu ? "-" + std::to_string(last) : "");
        cpu = last;
    }
    return text;
}

} // namespace chaintube::bench::realtime
