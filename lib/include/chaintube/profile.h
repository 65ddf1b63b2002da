// ChainTube — cross-section profiles (the shape of each ring).
#pragma once

#include "chaintube/types.h"

#include <vector>

namespace chaintube {

/// A closed 2D cross-section in the ring plane, in metres, centred on the axis point.
///
/// Ring coordinates: x along the ring's alignment vector, y along tangent × alignment.
/// Points go counter-clockwise seen from the hose's forward direction. Each point carries an
/// outward unit normal; a sharp corner is two points at the same place with different normals.
/// The seam (u = 0 and u = 1) is the first point; u grows with arc length around the profile.
class Profile
{
public:
    enum class Shape { Circle, Ellipse, Rectangle, RoundedRectangle, Polygon };

    /// Regular N-gon of smooth normals approximating a circle. radius > 0, 3 ≤ sides ≤ 1024.
    static Profile circle(double radius, int sides);
    /// Ellipse with semi-axes a (x) and b (y) > 0, 3 ≤ sides ≤ 1024.
    static Profile ellipse(double semiAxisX, double semiAxisY, int sides);
    /// Axis-aligned rectangle width × height > 0 with hard edges.
    static Profile rectangle(double width, double height);
    /// Rectangle with rounded corners of radius r (0 < r ≤ min(w, h)/2) and
    /// 1 ≤ cornerSegments ≤ 64 segments per corner.
    static Profile roundedRectangle(double width, double height, double cornerRadius,
                                    int cornerSegments);
    /// Any simple closed polygon (≥ 3 points, no repeated closing point, either orientation,
    /// non-zero area, not self-intersecting). Edges are hard (flat shaded) when
    /// smoothAngle = 0, otherwise corners whose turn is below smoothAngle (radians) get one
    /// averaged normal.
    static Profile polygon(const std::vector<Vec2>& points, double smoothAngle = 0.0);

    Shape shape() const { return m_shape; }
    /// Parameters the profile was made from (meaning depends on shape(); used by formats).
    const std::vector<double>& parameters() const { return m_parameters; }
    const std::vector<Vec2>& polygonPoints() const { return m_polygon; }

    /// Ring vertices, including a closing seam vertex equal to the first one (u = 1).
    int vertexCount() const { return static_cast<int>(m_points.size()); }
    const std::vector<Vec2>& points() const { return m_points; }
    const std::vector<Vec2>& normals() const { return m_normals; }
    const std::vector<double>& u() const { return m_u; }
    /// Largest distance of the profile from the axis (metres): the radius used for
    /// self-intersection checks and picking.
    double boundingRadius() const { return m_boundingRadius; }
    /// True if points j and j+1 span a face of the side surface (false between the two
    /// copies of a sharp corner). 0 ≤ j < vertexCount() − 1.
    bool isFaceEdge(int j) const { return m_faceEdge[static_cast<size_t>(j)] != 0; }
    /// The distinct corner positions of the outline, counter-clockwise in the (x, y) plane.
    const std::vector<Vec2>& corners() const { return m_corners; }
    /// Triangles (index triples into corners()) of the flat cap, counter-clockwise in the
    /// (x, y) plane, i.e. facing +tangent (the end cap); the start cap uses them reversed.
    const std::vector<int>& capTriangles() const { return m_capTriangles; }

    bool operator==(const Profile& o) const
    {
        return m_shape == o.m_shape && m_parameters == o.m_parameters && m_polygon == o.m_polygon;
    }

private:
    void finishSmooth(const std::vector<Vec2>& corners, const std::vector<Vec2>& normals);
    void finishHard(const std::vector<Vec2>& corners);
    void finish(); // computes u, face edges, bounding radius, cap triangulation
    Shape m_shape = Shape::Circle;
    std::vector<double> m_parameters;
    std::vector<Vec2> m_polygon;
    std::vector<Vec2> m_points;
    std::vector<Vec2> m_normals;
    std::vector<double> m_u;
    std::vector<unsigned char> m_faceEdge;
    std::vector<Vec2> m_corners;
    std::vector<int> m_capTriangles;
    double m_boundingRadius = 0.0;
};

} // namespace chaintube
