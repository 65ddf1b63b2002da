#include "chaintube/profile.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace chaintube {

namespace {

void requirePositive(double value, const char* name)
{
    if (!std::isfinite(value) || value <= 0.0)
        throw InvalidArgument(std::string("profile.") + name + ": expected a length > 0 m, got " +
                              std::to_string(value));
}

void requireSides(int sides)
{
    if (sides < 3 || sides > 1024)
        throw InvalidArgument("profile.sides: expected 3 … 1024, got " + std::to_string(sides));
}

double cross(const Vec2& a, const Vec2& b)
{
    return a.x() * b.y() - a.y() * b.x();
}

double signedArea(const std::vector<Vec2>& polygon)
{
    double area = 0.0;
    for (size_t i = 0; i < polygon.size(); ++i)
        area += cross(polygon[i], polygon[(i + 1) % polygon.size()]);
    return 0.5 * area;
}

bool segmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d)
{
    const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
    const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
    return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 &&
           d4 != 0;
}

bool pointInTriangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c)
{
    return cross(b - a, p - a) >= 0 && cross(c - b, p - b) >= 0 && cross(a - c, p - c) >= 0;
}

// Ear clipping of a simple counter-clockwise polygon; O(n²), profiles are small.
std::vector<int> triangulate(const std::vector<Vec2>& polygon)
{
    std::vector<int> remaining(polygon.size());
    for (size_t i = 0; i < polygon.size(); ++i)
        remaining[i] = static_cast<int>(i);
    std::vector<int> triangles;
    size_t guard = 0;
    while (remaining.size() > 3 && guard++ < polygon.size() * polygon.size()) {
        bool clipped = false;
        for (size_t i = 0; i < remaining.size(); ++i) {
            const int ia = remaining[(i + remaining.size() - 1) % remaining.size()];
            const int ib = remaining[i];
            const int ic = remaining[(i + 1) % remaining.size()];
            const Vec2 &a = polygon[ia], &b = polygon[ib], &c = polygon[ic];
            if (cross(b - a, c - b) <= 0) continue; // reflex or flat
            bool empty = true;
            for (int other : remaining) {
                if (other == ia || other == ib || other == ic) continue;
                if (pointInTriangle(polygon[other], a, b, c)) {
                    empty = false;
                    break;
                }
            }
            if (!empty) continue;
            triangles.insert(triangles.end(), {ia, ib, ic});
            remaining.erase(remaining.begin() + static_cast<long>(i));
            clipped = true;
            break;
        }
        if (!clipped) break; // numerically degenerate: fall back to a fan below
    }
    if (remaining.size() == 3) {
        triangles.insert(triangles.end(), {remaining[0], remaining[1], remaining[2]});
    } else {
        for (size_t i = 1; i + 1 < remaining.size(); ++i)
            triangles.insert(triangles.end(), {remaining[0], remaining[i], remaining[i + 1]});
    }
    return triangles;
}
} // namespace

void Profile::finishSmooth(const std::vector<Vec2>& corners, const std::vector<Vec2>& normals)
{
    m_corners = corners;
    m_points = corners;
    m_points.push_back(corners.front());
    m_normals = normals;
    m_normals.push_back(normals.front());
    finish();
}

void Profile::finishHard(const std::vector<Vec2>& corners)
{
    m_corners = corners;
    m_points.clear();
    m_normals.clear();
    for (size_t k = 0; k < corners.size(); ++k) {
        const Vec2& a = corners[k];
        const Vec2& b = corners[(k + 1) % corners.size()];
        const Vec2 edge = (b - a).normalized();
        const Vec2 normal(edge.y(), -edge.x()); // outward for a counter-clockwise outline
        m_points.push_back(a);
        m_points.push_back(b);
        m_normals.push_back(normal);
        m_normals.push_back(normal);
    }
    finish();
}

void Profile::finish()
{
    const size_t count = m_points.size();
    m_u.assign(count, 0.0);
    m_faceEdge.assign(count > 0 ? count - 1 : 0, 0);
    double total = 0.0;
    for (size_t j = 1; j < count; ++j) {
        const double step = (m_points[j] - m_points[j - 1]).norm();
        m_faceEdge[j - 1] = step > 0.0 ? 1 : 0;
        total += step;
        m_u[j] = total;
    }
    for (double& u : m_u)
        u = total > 0.0 ? u / total : 0.0;
    if (count > 0) m_u.back() = 1.0;
    m_boundingRadius = 0.0;
    for (const Vec2& p : m_points)
        m_boundingRadius = std::max(m_boundingRadius, p.norm());
    m_capTriangles = triangulate(m_corners);
}

Profile Profile::circle(double radius, int sides)
{
    requirePositive(radius, "radius");
    requireSides(sides);
    Profile profile;
    profile.m_shape = Shape::Circle;
    profile.m_parameters = {radius, static_cast<double>(sides)};
    std::vector<Vec2> corners, normals;
    for (int j = 0; j < sides; ++j) {
        const double angle = 2.0 * std::numbers::pi * j / sides;
        const Vec2 direction(std::cos(angle), std::sin(angle));
        corners.push_back(radius * direction);
        normals.push_back(direction);
    }
    profile.finishSmooth(corners, normals);
    return profile;
}

Profile Profile::ellipse(double semiAxisX, double semiAxisY, int sides)
{
    requirePositive(semiAxisX, "semiAxisX");
    requirePositive(semiAxisY, "semiAxisY");
    requireSides(sides);
    Profile profile;
    profile.m_shape = Shape::Ellipse;
    profile.m_parameters = {semiAxisX, semiAxisY, static_cast<double>(sides)};
    std::vector<Vec2> corners, normals;
    for (int j = 0; j < sides; ++j) {
        const double angle = 2.0 * std::numbers::pi * j / sides;
        const double c = std::cos(angle), s = std::sin(angle);
        corners.emplace_back(semiAxisX * c, semiAxisY * s);
        normals.push_back(Vec2(c / semiAxisX, s / semiAxisY).normalized());
    }
    profile.finishSmooth(corners, normals);
    return profile;
}

Profile Profile::rectangle(double width, double height)
{
    requirePositive(width, "width");
    requirePositive(height, "height");
    Profile profile;
    profile.m_shape = Shape::Rectangle;
    profile.m_parameters = {width, height};
    const double x = 0.5 * width, y = 0.5 * height;
    profile.finishHard({Vec2(x, -y), Vec2(x, y), Vec2(-x, y), Vec2(-x, -y)});
    return profile;
}

Profile Profile::roundedRectangle(double width, double height, double cornerRadius,
                                  int cornerSegments)
{
    requirePositive(width, "width");
    requirePositive(height, "height");
    requirePositive(cornerRadius, "cornerRadius");
    if (cornerRadius > 0.5 * std::min(width, height))
        throw InvalidArgument("profile.cornerRadius: expected at most min(width, height)/2 = " +
                              std::to_string(0.5 * std::min(width, height)) + " m, got " +
                              std::to_string(cornerRadius));
    if (cornerSegments < 1 || cornerSegments > 64)
        throw InvalidArgument("profile.cornerSegments: expected 1 … 64, got " +
                              std::to_string(cornerSegments));
    Profile profile;
    profile.m_shape = Shape::RoundedRectangle;
    profile.m_parameters = {width, height, cornerRadius, static_cast<double>(cornerSegments)};
    const double x = 0.5 * width - cornerRadius, y = 0.5 * height - cornerRadius;
    const Vec2 centres[4] = {Vec2(x, -y), Vec2(x, y), Vec2(-x, y), Vec2(-x, -y)};
    std::vector<Vec2> corners, normals;
    for (int c = 0; c < 4; ++c) {
        for (int k = 0; k <= cornerSegments; ++k) {
            const double angle =
                -0.5 * std::numbers::pi +
                0.5 * std::numbers::pi * (c + static_cast<double>(k) / cornerSegments);
            const Vec2 direction(std::cos(angle), std::sin(angle));
            const Vec2 point = centres[c] + cornerRadius * direction;
            // A corner radius of exactly half the side makes neighbouring arcs meet: skip the
            // duplicate so the outline stays simple.
            if (!corners.empty() && (point - corners.back()).norm() <= 1e-15 * width) continue;
            corners.push_back(point);
            normals.push_back(direction);
        }
    }
    if ((corners.front() - corners.back()).norm() <= 1e-15 * width) {
        corners.pop_back();
        normals.pop_back();
    }
    profile.finishSmooth(corners, normals);
    return profile;
}

Profile Profile::polygon(const std::vector<Vec2>& points, double smoothAngle)
{
    if (points.size() < 3)
        throw InvalidArgument("profile.points: expected at least 3 points, got " +
                              std::to_string(points.size()));
    if (!std::isfinite(smoothAngle) || smoothAngle < 0.0 || smoothAngle > std::numbers::pi)
        throw InvalidArgument("profile.smoothAngle: expected radians in [0, pi], got " +
                              std::to_string(smoothAngle));
    double extent = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
        if (!points[i].allFinite())
            throw InvalidArgument("profile.points[" + std::to_string(i) +
                                  "]: expected finite coordinates");
        extent = std::max(extent, points[i].norm());
    }
    for (size_t i = 0; i < points.size(); ++i) {
        if ((points[i] - points[(i + 1) % points.size()]).norm() <= 1e-12 * extent)
            throw InvalidArgument("profile.points[" + std::to_string(i) +
                                  "]: repeated point (do not repeat the first point at the end)");
    }
    const double area = signedArea(points);
    if (!(std::abs(area) > 1e-12 * extent * extent))
        throw InvalidArgument("profile.points: the polygon has zero area");
    const size_t n = points.size();
    for (size_t i = 0; i < n; ++i)
        for (size_t k = i + 1; k < n; ++k) {
            if (k == i + 1 || (i == 0 && k == n - 1)) continue;
            if (segmentsIntersect(points[i], points[(i + 1) % n], points[k], points[(k + 1) % n]))
                throw InvalidArgument("profile.points: edges " + std::to_string(i) + " and " +
                                      std::to_string(k) + " cross (expected a simple polygon)");
        }
    std::vector<Vec2> ccw = points;
    if (area < 0) std::reverse(ccw.begin(), ccw.end());

    Profile profile;
    profile.m_shape = Shape::Polygon;
    profile.m_parameters = {smoothAngle};
    profile.m_polygon = points;
    if (smoothAngle <= 0.0) {
        profile.finishHard(ccw);
        return profile;
    }
    // Mixed: corners turning less than smoothAngle share one averaged normal.
    profile.m_corners = ccw;
    std::vector<Vec2>& out = profile.m_points;
    std::vector<Vec2>& outNormals = profile.m_normals;
    auto edgeNormal = [&](size_t k) {
        const Vec2 e = (ccw[(k + 1) % n] - ccw[k]).normalized();
        return Vec2(e.y(), -e.x());
    };
    for (size_t k = 0; k <= n; ++k) {
        const size_t i = k % n;
        const Vec2 before = edgeNormal((i + n - 1) % n), after = edgeNormal(i);
        const double turn = std::acos(std::clamp(before.dot(after), -1.0, 1.0));
        if (turn < smoothAngle) {
            out.push_back(ccw[i]);
            outNormals.push_back((before + after).normalized());
        } else {
            if (k > 0) {
                out.push_back(ccw[i]);
                outNormals.push_back(before);
            }
            if (k < n) {
                out.push_back(ccw[i]);
                outNormals.push_back(after);
            }
        }
    }
    profile.finish();
    return profile;
}

} // namespace chaintube
