// A minimal log–log scatter/line plot written as SVG (no plotting library in Debian's C++ set).
#pragma once

#include <string>
#include <vector>

namespace chaintube::bench {

struct PlotSeries
{
    std::string label;
    std::string colour;                            ///< CSS colour
    std::vector<std::pair<double, double>> points; ///< (x, y), both > 0
    bool line = false;
};

/// Writes an SVG document with logarithmic x and y axes, a title, axis labels and a legend.
std::string logLogPlotSvg(const std::string& title, const std::string& xLabel,
                          const std::string& yLabel, const std::vector<PlotSeries>& series);

} // namespace chaintube::bench
