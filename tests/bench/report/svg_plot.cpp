#include "svg_plot.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace chaintube::bench {

std::string logLogPlotSvg(const std::string& title, const std::string& xLabel,
                          const std::string& yLabel, const std::vector<PlotSeries>& series)
{
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
    for (const PlotSeries& s : series)
        for (const auto& [x, y] : s.points) {
            if (!(x > 0) || !(y > 0)) continue;
            xMin = std::min(xMin, x), xMax = std::max(xMax, x), yMin = std::min(yMin, y),
            yMax = std::max(yMax, y);
        }
    if (xMin > xMax) xMin = 1, xMax = 10, yMin = 1, yMax = 10;
    const double lx0 = std::floor(std::log10(xMin)), lx1 = std::ceil(std::log10(xMax) + 1e-9);
    const double ly0 = std::floor(std::log10(yMin)), ly1 = std::ceil(std::log10(yMax) + 1e-9);
    const double width = 760, height = 480, left = 80, right = 220, top = 40, bottom = 60;
    auto px = [&](double x) {
        return left + (std::log10(x) - lx0) / std::max(1.0, lx1 - lx0) * (width - left - right);
    };
    auto py = [&](double y) {
        return height - bottom -
               (std::log10(y) - ly0) / std::max(1.0, ly1 - ly0) * (height - top - bottom);
    };
    std::ostringstream svg;
    svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
        << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
           "fill='white'/>\n";
    svg << "<text x='" << left << "' y='24' font-size='15'>" << title << "</text>\n";
    for (double e = lx0; e <= lx1; ++e) {
        const double x = px(std::pow(10.0, e));
        svg << "<line x1='" << x << "' y1='" << top << "' x2='" << x << "' y2='" << height - bottom
            << "' stroke='#ddd'/><text x='" << x - 14 << "' y='" << height - bottom + 16 << "'>1e"
            << e << "</text>\n";
    }
    for (double e = ly0; e <= ly1; ++e) {
        const double y = py(std::pow(10.0, e));
        svg << "<line x1='" << left << "' y1='" << y << "' x2='" << width - right << "' y2='" << y
            << "' stroke='#ddd'/><text x='" << left - 44 << "' y='" << y + 4 << "'>1e" << e
            << "</text>\n";
    }
    svg << "<rect x='" << left << "' y='" << top << "' width='" << width - left - right
        << "' height='" << height - top - bottom << "' fill='none' stroke='black'/>\n";
    svg << "<text x='" << (left + width - right) / 2 - 60 << "' y='" << height - 18 << "'>"
        << xLabel << "</text>\n";
    svg << "<text transform='translate(18," << (top + height - bottom) / 2 + 60 << ") rotate(-90)'>"
        << yLabel << "</text>\n";
    int row = 0;
    for (const PlotSeries& s : series) {
        std::vector<std::pair<double, double>> pts;
        for (const auto& p : s.points)
            if (p.first > 0 && p.second > 0) pts.push_back(p);
        if (s.line && pts.size() > 1) {
            svg << "<polyline fill='none' stroke='" << s.colour << "' stroke-width='1.5' points='";
            for (const auto& [x, y] : pts)
                svg << px(x) << "," << py(y) << " ";
            svg << "'/>\n";
        }
        for (const auto& [x, y] : pts)
            svg << "<circle cx='" << px(x) << "' cy='" << py(y) << "' r='3.5' fill='" << s.colour
                << "'/>\n";
        const double ly = top + 14 + 18 * row++;
        svg << "<circle cx='" << width - right + 16 << "' cy='" << ly - 4 << "' r='4' fill='"
            << s.colour << "'/><text x='" << width - right + 26 << "' y='" << ly << "'>" << s.label
            << "</text>\n";
    }
    svg << "</svg>\n";
    return svg.str();
}

} // namespace chaintube::bench
