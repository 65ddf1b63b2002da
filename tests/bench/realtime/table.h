// chaintube-bench-realtime: the table of results, as Markdown and as CSV. Each column is one
// entry of columns(): a header for each format and how a row fills it, so a new figure (e.g. a
// per-update work counter) is one more entry.
#pragma once

#include "cases.h"

#include <functional>
#include <string>
#include <vector>

namespace chaintube::bench::realtime {

/// Median, 99th percentile (nearest rank) and largest of a run's frame times, and their mean
/// (microseconds). All 0 for no frames.
struct TimeSummary
{
    double median = 0.0, p99 = 0.0, worst = 0.0, mean = 0.0;
    static TimeSummary of(std::vector<double> microseconds);
};

/// A row's frame times summarised: wall clock and thread CPU time (FrameTimer).
struct RowTimes
{
    TimeSummary wall, cpu;
    static RowTimes of(const Row& row);
};

/// One column: its header and cell in each format; an empty header leaves the column out of
/// that format (e.g. the Markdown shows the status counts in one cell, the CSV one per column).
struct Column
{
    std::string markdownHeader;
    std::string csvHeader; ///< no commas
    std::function<std::string(const Row&, const RowTimes&)> markdown;
    std::function<std::string(const Row&, const RowTimes&)> csv; ///< no commas
};
const std::vector<Column>& columns();

std::string markdownTable(const std::vector<Row>& rows);
std::string csvTable(const std::vector<Row>& rows);

/// "1.42 µs", "249 µs", "6.31 ms": three significant digits.
std::string formatMicroseconds(double microseconds);

} // namespace chaintube::bench::realtime
