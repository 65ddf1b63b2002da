#include "table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace chaintube::bench::realtime {

namespace {
const std::string kNotApplicable = "—";

std::string printf1(const char* format, double value)
{
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, value);
    return buffer;
}

// Markdown: two significant digits, exactly 0 as "0".
std::string small(double value)
{
    return value == 0.0 ? std::string("0") : printf1("%.2g", value);
}

// CSV: six significant digits.
std::string number(double value)
{
    return printf1("%.6g", value);
}

// Nearest-rank percentile of a work counter (q = 1: the largest); 0 for none.
int percentile(std::vector<int> values, double q)
{
    if (values.empty()) return 0;
    const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(values.size())));
    const size_t k = std::min(values.size() - 1, rank > 0 ? rank - 1 : 0);
    std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
    return values[k];
}

// A work percentile over the median work (a median of 0 counts as 1), one decimal.
std::string ratio(const std::vector<int>& work, double q)
{
    return printf1("%.1f",
                   static_cast<double>(percentile(work, q)) / std::max(1, percentile(work, 0.5)));
}

std::string statuses(const std::array<int, 4>& counts)
{
    std::string text = std::to_string(counts[0]) + " / " + std::to_string(counts[1]) + " / " +
                       std::to_string(counts[2]);
    if (counts[3] > 0) text += " / invalid " + std::to_string(counts[3]);
    return text;
}

Column markdownOnly(std::string header,
                    std::function<std::string(const Row&, const RowTimes&)> markdown)
{
    return {std::move(header), "", std::move(markdown), {}};
}

Column csvOnly(std::string header, std::function<std::string(const Row&, const RowTimes&)> csv)
{
    return {"", std::move(header), {}, std::move(csv)};
}

// A status count: the Markdown shows the counts together (grabStatuses / stepStatuses).
Column statusCount(const std::string& header, bool step, int status)
{
    return csvOnly(header, [step, status](const Row& row, const RowTimes&) {
        const bool counted = step ? row.checks.stepped : row.checks.hasStatuses;
        const std::array<int, 4>& counts = step ? row.checks.stepStatuses : row.checks.grabStatuses;
        return counted ? std::to_string(counts[static_cast<size_t>(status)]) : std::string();
    });
}
} // namespace

TimeSummary TimeSummary::of(std::vector<double> microseconds)
{
    TimeSummary summary;
    if (microseconds.empty()) return summary;
    std::sort(microseconds.begin(), microseconds.end());
    const size_t n = microseconds.size();
    summary.median =
        n % 2 ? microseconds[n / 2] : 0.5 * (microseconds[n / 2 - 1] + microseconds[n / 2]);
    // Nearest rank: the smallest value with at least 99 % of the frames at or below it.
    const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(n)));
    summary.p99 = microseconds[std::max<size_t>(rank, 1) - 1];
    summary.worst = microseconds.back();
    summary.mean =
        std::accumulate(microseconds.begin(), microseconds.end(), 0.0) / static_cast<double>(n);
    return summary;
}

RowTimes RowTimes::of(const Row& row)
{
    return {TimeSummary::of(row.checks.microseconds), TimeSummary::of(row.checks.cpuMicroseconds)};
}

std::string formatMicroseconds(double microseconds)
{
    if (microseconds >= 1000.0) {
        const double ms = microseconds / 1000.0;
        return printf1(ms >= 100.0 ? "%.0f ms" : ms >= 10.0 ? "%.1f ms" : "%.2f ms", ms);
    }
    return printf1(microseconds >= 100.0  ? "%.0f µs"
                   : microseconds >= 10.0 ? "%.1f µs"
                                          : "%.2f µs",
                   microseconds);
}

const std::vector<Column>& columns()
{
    using R = const Row&;
    using T = const RowTimes&;
    static const std::vector<Column> all = {
        {"case", "case", [](R r, T) { return r.caseId; }, [](R r, T) { return r.caseId; }},
        {"points", "points", [](R r, T) { return std::to_string(r.points); },
         [](R r, T) { return std::to_string(r.points); }},
        {"solver", "solver", [](R r, T) { return r.solver; }, [](R r, T) { return r.solver; }},
        {"frames", "frames", [](R r, T) { return std::to_string(r.checks.microseconds.size()); },
         [](R r, T) { return std::to_string(r.checks.microseconds.size()); }},
        csvOnly("updates", [](R r, T) { return std::to_string(r.checks.updates); }),
        {"median", "median_us", [](R, T t) { return formatMicroseconds(t.wall.median); },
         [](R, T t) { return number(t.wall.median); }},
        {"p99", "p99_us", [](R, T t) { return formatMicroseconds(t.wall.p99); },
         [](R, T t) { return number(t.wall.p99); }},
        {"worst", "worst_us", [](R, T t) { return formatMicroseconds(t.wall.worst); },
         [](R, T t) { return number(t.wall.worst); }},
        {"mean", "mean_us", [](R, T t) { return formatMicroseconds(t.wall.mean); },
         [](R, T t) { return number(t.wall.mean); }},
        {"CPU median", "cpu_median_us", [](R, T t) { return formatMicroseconds(t.cpu.median); },
         [](R, T t) { return number(t.cpu.median); }},
        {"CPU p99", "cpu_p99_us", [](R, T t) { return formatMicroseconds(t.cpu.p99); },
         [](R, T t) { return number(t.cpu.p99); }},
        {"CPU worst", "cpu_worst_us", [](R, T t) { return formatMicroseconds(t.cpu.worst); },
         [](R, T t) { return number(t.cpu.worst); }},
        {"max length violation (rel.)", "length_violation_max",
         [](R r, T) { return small(r.checks.lengthViolation); },
         [](R r, T) { return number(r.checks.lengthViolation); }},
        {"max bend violation (rad)", "bend_violation_max_rad",
         [](R r, T) { return small(r.checks.bendViolation); },
         [](R r, T) { return number(r.checks.bendViolation); }},
        {"NaN/Inf updates", "nonfinite_updates",
         [](R r, T) { return std::to_string(r.checks.nonFinite); },
         [](R r, T) { return std::to_string(r.checks.nonFinite); }},
        markdownOnly("grabs Ok / Clamped / Infeasible",
                     [](R r, T) {
                         return r.checks.hasStatuses ? statuses(r.checks.grabStatuses)
                                                     : kNotApplicable;
                     }),
        statusCount("grab_ok", false, 0),
        statusCount("grab_clamped", false, 1),
        statusCount("grab_infeasible", false, 2),
        statusCount("grab_invalid", false, 3),
        markdownOnly("steps Ok / Clamped / Infeasible",
                     [](R r, T) {
                         return r.checks.stepped ? statuses(r.checks.stepStatuses) : kNotApplicable;
                     }),
        statusCount("step_ok", true, 0),
        statusCount("step_clamped", true, 1),
        statusCount("step_infeasible", true, 2),
        statusCount("step_invalid", true, 3),
        {"mean grab error (m)", "grab_error_mean_m",
         [](R r, T) {
             return small(r.checks.updates ? r.checks.grabErrorSum / r.checks.updates : 0.0);
         },
         [](R r, T) {
             return number(r.checks.updates ? r.checks.grabErrorSum / r.checks.updates : 0.0);
         }},
        csvOnly("grab_error_max_m", [](R r, T) { return number(r.checks.grabErrorMax); }),
        {"floor penetration (m)", "floor_penetration_max_m",
         [](R r, T) {
             return r.checks.hasFloor ? small(r.checks.floorPenetration) : kNotApplicable;
         },
         [](R r, T) {
             return r.checks.hasFloor ? number(r.checks.floorPenetration) : std::string();
         }},
        {"Newton steps an update (median / max)", "iterations_median",
         [](R r, T) {
             return r.checks.hasStatuses
                        ? std::to_string(percentile(r.checks.iterations, 0.5)) + " / " +
                              std::to_string(percentile(r.checks.iterations, 1.0))
                        : kNotApplicable;
         },
         [](R r, T) {
             return r.checks.hasStatuses ? std::to_string(percentile(r.checks.iterations, 0.5))
                                         : std::string();
         }},
        csvOnly("iterations_max",
                [](R r, T) {
                    return r.checks.hasStatuses
                               ? std::to_string(percentile(r.checks.iterations, 1.0))
                               : std::string();
                }),
        {"work p99 / median, worst / median", "work_p99_over_median",
         [](R r, T) {
             return r.checks.frameWork.empty()
                        ? kNotApplicable
                        : ratio(r.checks.frameWork, 0.99) + " / " + ratio(r.checks.frameWork, 1.0);
         },
         [](R r, T) {
             return r.checks.frameWork.empty() ? std::string() : ratio(r.checks.frameWork, 0.99);
         }},
        csvOnly("work_worst_over_median",
                [](R r, T) {
                    return r.checks.frameWork.empty() ? std::string()
                                                      : ratio(r.checks.frameWork, 1.0);
                }),
        {"frames to meet a held target", "held_target_frames",
         [](R r, T) {
             if (r.checks.heldFrames < 0) return std::string(kNotApplicable);
             if (r.checks.heldFrames > FrameChecks::kHeldFrameLimit)
                 return "> " + std::to_string(FrameChecks::kHeldFrameLimit);
             return std::to_string(r.checks.heldFrames);
         },
         [](R r, T) {
             return r.checks.heldFrames < 0 ? std::string() : std::to_string(r.checks.heldFrames);
         }},
        csvOnly("blocked_updates",
                [](R r, T) {
                    return r.checks.hasStatuses ? std::to_string(r.checks.blocked) : std::string();
                }),
        {"status contradicted", "status_contradicted",
         [](R r, T) {
             return r.checks.statusContradicted < 0 ? kNotApplicable
                                                    : std::to_string(r.checks.statusContradicted);
         },
         [](R r, T) {
             return r.checks.statusContradicted < 0 ? std::string()
                                                    : std::to_string(r.checks.statusContradicted);
         }},
        csvOnly("checker_disagreement",
                [](R r, T) {
                    return r.checks.checkerDisagreement < 0 ? std::string()
                                                            : number(r.checks.checkerDisagreement);
                }),
    };
    return all;
}

std::string markdownTable(const std::vector<Row>& rows)
{
    std::ostringstream out;
    std::string rule = "|";
    out << "|";
    for (const Column& column : columns())
        if (column.markdown) {
            out << " " << column.markdownHeader << " |";
            rule += "---|";
        }
    out << "\n" << rule << "\n";
    for (const Row& row : rows) {
        const RowTimes summary = RowTimes::of(row);
        out << "|";
        for (const Column& column : columns())
            if (column.markdown) out << " " << column.markdown(row, summary) << " |";
        out << "\n";
    }
    return out.str();
}

std::string csvTable(const std::vector<Row>& rows)
{
    std::ostringstream out;
    bool first = true;
    for (const Column& column : columns())
        if (column.csv) {
            out << (first ? "" : ",") << column.csvHeader;
            first = false;
        }
    out << "\n";
    for (const Row& row : rows) {
        const RowTimes summary = RowTimes::of(row);
        first = true;
        for (const Column& column : columns())
            if (column.csv) {
                out << (first ? "" : ",") << column.csv(row, summary);
                first = false;
            }
        out << "\n";
    }
    return out.str();
}

} // namespace chaintube::bench::realtime
