// chaintube-bench-realtime: time per frame (median, p99, worst) of the calls a VR platform makes
// every frame, beside what each frame leaves (violations, statuses, grab error), ChainTube
// against an XPBD rod on the same inputs, and the 50-hose engine sample through the runtime.
// README.md beside this file has the definitions and how to read the table.
//
//   taskset -c 1 ./build/tests/bench/chaintube-bench-realtime [-o DIR] [--frames N] [--quick] …
#include "cases.h"
#include "engine.h"
#include "machine.h"
#include "table.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <unistd.h>

using namespace chaintube;
using namespace chaintube::bench::realtime;

namespace {

#ifndef CHAINTUBE_SCENES_DIR
#define CHAINTUBE_SCENES_DIR ""
#endif
#ifndef CHAINTUBE_SAMPLES_DIR
#define CHAINTUBE_SAMPLES_DIR ""
#endif

#ifdef __clang__
const char* const kCompiler = "Clang " __clang_version__;
#else
const char* const kCompiler = "GCC " __VERSION__;
#endif

const char* const kUsage =
    "usage: chaintube-bench-realtime [--quick] [-o DIR] [--frames N] [--warmup N] [--points LIST]\n"
    "                                [--sweeps LIST|none] [--case ID]... [--cpu N] [--commit "
    "TEXT]\n"
    "                                [--scenes DIR]\n"
    "Prints a Markdown table of time per frame (median, p99, worst, mean) with the checks of "
    "every\n"
    "frame; with -o also writes DIR/realtime.md and DIR/realtime.csv.\n"
    "  --frames N     timed frames per row (default 2000; --quick: 50)\n"
    "  --warmup N     frames run first on a separate hose (default frames/20, at least 10)\n"
    "  --points LIST  axis points of the hose cases (default 25,100,400; --quick: 25,100)\n"
    "  --sweeps LIST  XPBD sweeps per frame (default 4,16,64); none: no XPBD rows\n"
    "  --case ID      only this case (repeatable): free-drag, ends-fixed, ends-fixed-gravity,\n"
    "                 ends-fixed-floor, ends-fixed-gravity-floor, ends-fixed-clip,\n"
    "                 held-end-gravity, engine-50\n"
    "  --budget N     Newton steps an update may take (Hose::setBudget; default: the real-time\n"
    "                 default, UpdateBudget::realtime()); none: no bound\n"
    "  --cpu N        pin the process to CPU N (sched_setaffinity; or run under taskset -c N)\n"
    "  --commit TEXT  the commit to name in the header (default: git rev-parse in the source "
    "tree)\n"
    "  --scenes DIR   folder with 2CylinderEngine.glb (default: CMake's CHAINTUBE_SCENES_DIR)\n"
    "  --quick        a short run (CI): 50 frames, 25 and 100 points\n"
    "Exits 1 when a consistency check fails (listed on stderr and in the report), 2 on bad "
    "usage.\n";

struct Options
{
    bool quick = false;
    std::filesystem::path outDir;
    int frames = -1, warmup = -1;
    std::vector<int> points, sweeps;
    bool sweepsGiven = false;
    std::vector<std::string> cases;
    int cpu = -1;
    std::string commit;
    std::filesystem::path scenes = CHAINTUBE_SCENES_DIR;
};

std::vector<int> parseList(const std::string& text)
{
    std::vector<int> values;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        size_t used = 0;
        const int value = std::stoi(item, &used);
        if (used != item.size() || value <= 0) throw std::invalid_argument(item);
        values.push_back(value);
    }
    if (values.empty()) throw std::invalid_argument(text);
    return values;
}

int parseCount(const std::string& text, int least)
{
    size_t used = 0;
    const int value = std::stoi(text, &used);
    if (used != text.size() || value < least) throw std::invalid_argument(text);
    return value;
}

bool wanted(const Options& options, const std::string& id)
{
    return options.cases.empty() ||
           std::find(options.cases.begin(), options.cases.end(), id) != options.cases.end();
}

std::string commandLine(int argc, char** argv)
{
    std::string text;
    for (int i = 0; i < argc; ++i) {
        const std::string arg = argv[i];
        const bool plain = !arg.empty() && arg.find_first_of(" \t'\"\\$`") == std::string::npos;
        text += (i ? " " : "") + (plain ? arg : "'" + arg + "'");
    }
    return text;
}

// What can honestly fail without measuring speed: every frame timed and checked, every
// status counted, the benchmark's own violation measure agreeing with Hose::measureViolation,
// statuses that say the constraints hold agreeing with the measured violation, no NaN or Inf.
std::vector<std::string> consistencyProblems(const std::vector<Row>& rows, int frames)
{
    std::vector<std::string> problems;
    for (const Row& row : rows) {
        const std::string name =
            row.caseId + " / " + std::to_string(row.points) + " points / " + row.solver + ": ";
        const FrameChecks& c = row.checks;
        if (static_cast<int>(c.microseconds.size()) != frames ||
            c.cpuMicroseconds.size() != c.microseconds.size())
            problems.push_back(name + std::to_string(c.microseconds.size()) + " frames timed (" +
                               std::to_string(c.cpuMicroseconds.size()) + " in CPU time), not " +
                               std::to_string(frames));
        auto validTimes = [](const std::vector<double>& times) {
            const TimeSummary t = TimeSummary::of(times);
            return std::all_of(times.begin(), times.end(),
                               [](double us) { return std::isfinite(us) && us >= 0.0; }) &&
                   t.median <= t.p99 && t.p99 <= t.worst;
        };
        if (!validTimes(c.microseconds) || !validTimes(c.cpuMicroseconds))
            problems.push_back(name +
                               "frame times not finite and ordered (median <= p99 <= worst)");
        if (c.updates != frames * row.updatesPerFrame)
            problems.push_back(name + std::to_string(c.updates) + " updates checked, not " +
                               std::to_string(frames * row.updatesPerFrame));
        auto sum = [](const std::array<int, 4>& counts) {
            return counts[0] + counts[1] + counts[2] + counts[3];
        };
        if (c.hasStatuses && sum(c.grabStatuses) != c.updates)
            problems.push_back(name + "grab statuses add up to " +
                               std::to_string(sum(c.grabStatuses)) + ", not " +
                               std::to_string(c.updates));
        if (c.stepped && sum(c.stepStatuses) != c.updates)
            problems.push_back(name + "step statuses add up to " +
                               std::to_string(sum(c.stepStatuses)) + ", not " +
                               std::to_string(c.updates));
        if (c.hasStatuses && c.grabStatuses[static_cast<size_t>(Status::InvalidInput)] > 0)
            problems.push_back(name + "grabs rejected as InvalidInput");
        if (c.nonFinite > 0)
            problems.push_back(name + std::to_string(c.nonFinite) + " updates left NaN or Inf");
        if (!(std::isfinite(c.lengthViolation) && std::isfinite(c.bendViolation) &&
              std::isfinite(c.grabErrorSum)))
            problems.push_back(name + "violation or grab error not finite");
        if (c.checkerDisagreement > 1e-8)
            problems.push_back(name +
                               "own violation measure and Hose::measureViolation differ by " +
                               std::to_string(c.checkerDisagreement));
        if (c.overBudget > 0)
            problems.push_back(name + std::to_string(c.overBudget) +
                               " updates took more Newton steps than the stated budget of " +
                               std::to_string(c.budget));
        if (c.statusContradicted > 0)
            problems.push_back(name + std::to_string(c.statusContradicted) +
                               " updates returned Ok or Clamped with a constraint violated beyond "
                               "the status's promise");
    }
    return problems;
}

// The written files read back: both present, the CSV with a header and one line per row, every
// line with as many fields as the header.
std::vector<std::string> outputProblems(const std::filesystem::path& dir, size_t rows)
{
    std::vector<std::string> problems;
    if (!std::filesystem::is_regular_file(dir / "realtime.md") ||
        std::filesystem::file_size(dir / "realtime.md") == 0)
        problems.push_back("realtime.md missing or empty");
    std::ifstream csv(dir / "realtime.csv");
    std::vector<std::string> lines;
    for (std::string line; std::getline(csv, line);)
        lines.push_back(line);
    if (lines.size() != rows + 1)
        problems.push_back("realtime.csv has " + std::to_string(lines.size()) + " lines, not " +
                           std::to_string(rows + 1));
    for (const std::string& line : lines)
        if (std::count(line.begin(), line.end(), ',') !=
            std::count(lines.front().begin(), lines.front().end(), ','))
            problems.push_back("realtime.csv: a line's field count differs from the header's");
    return problems;
}

void writeFile(const std::filesystem::path& path, const std::string& text)
{
    std::ofstream out(path);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string mdCode(const std::string& text)
{
    return "`" + text + "`";
}

} // namespace

int main(int argc, char** argv)
{
    Options options;
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
                return argv[++i];
            };
            if (arg == "--quick")
                options.quick = true;
            else if (arg == "-o")
                options.outDir = value();
            else if (arg == "--frames")
                options.frames = parseCount(value(), 1);
            else if (arg == "--warmup")
                options.warmup = parseCount(value(), 0);
            else if (arg == "--points")
                options.points = parseList(value());
            else if (arg == "--sweeps") {
                const std::string list = value();
                options.sweeps = list == "none" ? std::vector<int>{} : parseList(list);
                options.sweepsGiven = true;
            } else if (arg == "--case")
                options.cases.push_back(value());
            else if (arg == "--budget") {
                const std::string text = value();
                benchBudget() = text == "none" ? UpdateBudget{} : UpdateBudget{std::stoi(text)};
                if (benchBudget().newtonSteps < 0)
                    throw std::invalid_argument("--budget: a number of Newton steps >= 0 or none");
            } else if (arg == "--cpu")
                options.cpu = parseCount(value(), 0);
            else if (arg == "--commit")
                options.commit = value();
            else if (arg == "--scenes")
                options.scenes = value();
            else if (arg == "--help" || arg == "-h") {
                std::cout << kUsage;
                return 0;
            } else
                throw std::invalid_argument("unknown option " + arg);
        }
        for (const std::string& id : options.cases) {
            const auto& cases = hoseCases();
            if (id != "engine-50" && std::none_of(cases.begin(), cases.end(),
                                                  [&](const HoseCase& c) { return c.id == id; }))
                throw std::invalid_argument("unknown case " + id);
        }
        for (int n : options.points)
            if (n < 5) throw std::invalid_argument("--points: at least 5 points");
    } catch (const std::exception& e) {
        std::cerr << "chaintube-bench-realtime: " << e.what() << "\n" << kUsage;
        return 2;
    }
    if (options.frames < 0) options.frames = options.quick ? 50 : 2000;
    if (options.warmup < 0) options.warmup = options.quick ? 5 : std::max(10, options.frames / 20);
    if (options.points.empty())
        options.points = options.quick ? std::vector<int>{25, 100} : std::vector<int>{25, 100, 400};
    if (!options.sweepsGiven) options.sweeps = {4, 16, 64};

    if (options.cpu >= 0) {
        std::string error;
        if (!pinToCpu(options.cpu, error)) {
            std::cerr << "chaintube-bench-realtime: cannot pin to CPU " << options.cpu << ": "
                      << error << "\n";
            return 2;
        }
    }
    const std::string commit =
        options.commit.empty() ? gitCommit(CHAINTUBE_SOURCE_DIR) : options.commit;
    const std::string date = utcDate(), loadAtStart = loadAverage(), cpus = allowedCpus();

    try {
        std::vector<Row> rows;
        auto add = [&](Row row) {
            const TimeSummary t = TimeSummary::of(row.checks.microseconds);
            const TimeSummary cpu = TimeSummary::of(row.checks.cpuMicroseconds);
            std::cerr << row.caseId << " / " << row.points << " points / " << row.solver
                      << ": median " << formatMicroseconds(t.median) << ", p99 "
                      << formatMicroseconds(t.p99) << ", worst " << formatMicroseconds(t.worst)
                      << " (CPU time: median " << formatMicroseconds(cpu.median) << ", p99 "
                      << formatMicroseconds(cpu.p99) << ", worst " << formatMicroseconds(cpu.worst)
                      << ")\n";
            rows.push_back(std::move(row));
        };
        for (const HoseCase& hoseCase : hoseCases()) {
            if (!wanted(options, hoseCase.id)) continue;
            for (int points : options.points) {
                add(runChainTube(hoseCase, points, options.frames, options.warmup));
                if (hoseCase.clip) continue; // the XPBD rod has no sliding clip
                for (int sweeps : options.sweeps)
                    add(runXpbd(hoseCase, points, sweeps, options.frames, options.warmup));
            }
        }
        EngineResult engine;
        if (wanted(options, "engine-50")) {
            const std::filesystem::path work =
                (options.outDir.empty() ? std::filesystem::temp_directory_path() : options.outDir) /
                (".engine-export-" + std::to_string(getpid()));
            engine = runEngine(options.scenes, CHAINTUBE_SAMPLES_DIR, work, options.frames,
                               options.warmup);
            if (engine.ran)
                add(engine.row);
            else
                std::cerr << "engine-50: skipped: " << engine.skipped << "\n";
        }
        // The machine's floor at the targets' median and p99 (README.md beside this file,
        // "Timing").
        struct Floor
        {
            double microseconds;
            TimeSummary wall, cpu;
        };
        std::vector<Floor> floors;
        for (const double microseconds : {15.0, 50.0}) {
            const FrameChecks work = runFixedWork(microseconds, options.frames, options.warmup);
            floors.push_back({microseconds, TimeSummary::of(work.microseconds),
                              TimeSummary::of(work.cpuMicroseconds)});
            std::cerr << "fixed work of " << microseconds << " µs: median "
                      << formatMicroseconds(floors.back().wall.median) << ", p99 "
                      << formatMicroseconds(floors.back().wall.p99) << ", worst "
                      << formatMicroseconds(floors.back().wall.worst) << "\n";
        }
        const std::string loadAtEnd = loadAverage();

        std::vector<std::string> problems = consistencyProblems(rows, options.frames);
        for (const Floor& f : floors)
            if (!(f.cpu.median >= 0.25 * f.microseconds && f.cpu.median <= 10.0 * f.microseconds))
                problems.push_back("the fixed work calibrated to " +
                                   formatMicroseconds(f.microseconds) + " took a median of " +
                                   formatMicroseconds(f.cpu.median) + " of CPU time a frame");
        std::ostringstream md;
        md << "# Real-time benchmark: time per frame beside what each frame leaves\n\n"
           << "| | |\n|---|---|\n"
           << "| commit | " << commit << " |\n"
           << "| date | " << date << " |\n"
           << "| CPU | " << cpuModel() << " |\n"
           << "| CPUs the process ran on | " << cpus << " |\n"
           << "| command | " << mdCode(commandLine(argc, argv)) << " |\n"
           << "| build | " << CHAINTUBE_BUILD_TYPE << ", " << kCompiler << " |\n"
           << "| frames | " << options.frames << " timed per row, after " << options.warmup
           << " warm-up frames on a separate hose |\n"
           << "| load average (1 min) | " << loadAtStart << " at the start, " << loadAtEnd
           << " at the end |\n\n"
           << "Times are per frame: a hose case's grab (and, with gravity, its `Hose::step()`); "
              "an XPBD rod's step; the engine's 50 grabs and `HoseRuntime::update()`. The checks "
              "run after each frame, outside the timed region. Definitions and how to read the "
              "columns: `tests/bench/realtime/README.md`.\n\n";
        const int summaryPoints =
            std::find(options.points.begin(), options.points.end(), 100) != options.points.end()
                ? 100
                : options.points.front();
        std::vector<Row> summary;
        for (const Row& row : rows)
            if ((row.solver == "ChainTube" && row.points == summaryPoints) ||
                row.caseId == "engine-50")
                summary.push_back(row);
        md << "## ChainTube, " << summaryPoints << " points, and the engine sample\n\n"
           << markdownTable(summary) << "\n";
        md << "## Every row (ChainTube and the XPBD rod at " << summaryPoints
           << " and the other resolutions)\n\n"
           << markdownTable(rows) << "\n";
        md << "## The engine sample\n\n";
        if (engine.ran)
            md << "`samples/engine-50-hoses.ctproj` exported to a GLB hose rig and loaded by "
                  "`rig::HoseRuntime`: "
               << engine.hoses << " hoses, " << engine.row.points << " axis points, "
               << engine.grabbedHoses << " of them grabbed every frame (at the grabbable point "
               << "nearest the middle, each on its own walk), " << engine.gravityHoses
               << " with gravity, " << engine.colliders << " collider objects. A frame is the "
               << "grabs plus `HoseRuntime::update()`: a `Hose::step()` for every hose with "
               << "gravity, then the surface (rings and normals) and the joint poses of every "
               << "changed hose. Largest violation as loaded: length " << engine.loaded.length
               << ", bend " << engine.loaded.bend << " rad.\n\n";
        else if (wanted(options, "engine-50"))
            md << "Skipped: " << engine.skipped << ".\n\n";
        else
            md << "Not run (--case).\n\n";
        md << "## The machine's floor\n\n"
           << "The same arithmetic every frame (a chain of dependent multiply-adds calibrated to "
              "the length in the first column), timed back to back as the cases are. Its work "
              "never varies, so what its p99 and worst add to its median is this machine's "
              "(interrupts, the hypervisor, the clocks), and a case's frame of that length "
              "carries it too.\n\n"
           << "| fixed work a frame | frames | median | p99 | worst | CPU median | CPU p99 | CPU "
              "worst |\n|---|---|---|---|---|---|---|---|\n";
        for (const Floor& f : floors)
            md << "| " << formatMicroseconds(f.microseconds) << " | " << options.frames << " | "
               << formatMicroseconds(f.wall.median) << " | " << formatMicroseconds(f.wall.p99)
               << " | " << formatMicroseconds(f.wall.worst) << " | "
               << formatMicroseconds(f.cpu.median) << " | " << formatMicroseconds(f.cpu.p99)
               << " | " << formatMicroseconds(f.cpu.worst) << " |\n";
        md << "\n";
        md << "## Consistency checks\n\n";
        if (problems.empty())
            md << "Passed: every frame timed and checked, every status counted, no NaN or Inf, "
                  "the benchmark's violation measure agrees with `Hose::measureViolation()` (to "
                  "1e-8), no update that returned Ok or Clamped left a violation beyond that "
                  "status's promise, and no update of a case with a stated budget took more "
                  "Newton steps than it.\n";
        else
            for (const std::string& problem : problems)
                md << "* " << problem << "\n";

        std::cout << md.str();
        if (!options.outDir.empty()) {
            std::filesystem::create_directories(options.outDir);
            writeFile(options.outDir / "realtime.md", md.str());
            writeFile(options.outDir / "realtime.csv", csvTable(rows));
            const std::vector<std::string> written = outputProblems(options.outDir, rows.size());
            problems.insert(problems.end(), written.begin(), written.end());
        }
        for (const std::string& problem : problems)
            std::cerr << "consistency: " << problem << "\n";
        return problems.empty() ? 0 : 1;
    } catch (const std::exception& e) {
        std::cerr << "chaintube-bench-realtime: " << e.what() << "\n";
        return 1;
    }
}
