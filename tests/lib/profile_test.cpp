#include "test_util.h"

#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

namespace {
double capArea(const Profile& profile)
{
    double area = 0.0;
    const auto& c = profile.corners();
    const auto& t = profile.capTriangles();
    for (size_t k = 0; k < t.size(); k += 3) {
        const Vec2 a = c[t[k]], b = c[t[k + 1]], d = c[t[k + 2]];
        const double signedArea = 0.5 * ((b - a).x() * (d - a).y() - (b - a).y() * (d - a).x());
        EXPECT_GT(signedArea, 0.0) << "cap triangles are counter-clockwise";
        area += signedArea;
    }
    return area;
}
} // namespace

TEST(Profile, CircleHasSidesPlusSeamVerticesWithRadialNormals)
{
    const Profile p = Profile::circle(0.01, 16);
    EXPECT_EQ(p.vertexCount(), 17);
    EXPECT_EQ(p.points().front(), p.points().back());
    EXPECT_EQ(p.u().front(), 0.0);
    EXPECT_EQ(p.u().back(), 1.0);
    for (int j = 0; j < 16; ++j) {
        EXPECT_NEAR(p.points()[j].norm(), 0.01, 1e-15);
        EXPECT_NEAR(p.normals()[j].dot(p.points()[j].normalized()), 1.0, 1e-12);
    }
    EXPECT_NEAR(capArea(p), 0.5 * 16 * 0.01 * 0.01 * std::sin(2 * std::numbers::pi / 16), 1e-15);
}

TEST(Profile, RectangleHasHardEdgesAndNoZeroWidthFaces)
{
    const Profile p = Profile::rectangle(0.04, 0.02);
    EXPECT_EQ(p.vertexCount(), 8);
    int faces = 0;
    for (int j = 0; j + 1 < p.vertexCount(); ++j)
        faces += p.isFaceEdge(j);
    EXPECT_EQ(faces, 4);
    EXPECT_NEAR(capArea(p), 0.04 * 0.02, 1e-15);
    EXPECT_NEAR(p.boundingRadius(), std::hypot(0.02, 0.01), 1e-15);
}

TEST(Profile, EllipseAndRoundedRectangleAreaMatchTheirShape)
{
    EXPECT_NEAR(capArea(Profile::ellipse(0.02, 0.01, 256)), std::numbers::pi * 0.02 * 0.01, 1e-7);
    const double r = 0.005;
    // Four quarter arcs of 32 segments make an inscribed 128-gon of radius r.
    EXPECT_NEAR(capArea(Profile::roundedRectangle(0.04, 0.02, r, 32)),
                0.04 * 0.02 - 4 * r * r + 64 * r * r * std::sin(2 * std::numbers::pi / 128), 1e-15);
    // Radius of half the smaller side: the straight part of that side vanishes.
    EXPECT_NO_THROW(Profile::roundedRectangle(0.04, 0.02, 0.01, 4));
}

TEST(Profile, ConcavePolygonCapIsTriangulatedExactly)
{
    // An L shape, given clockwise: it is reoriented.
    const std::vector<Vec2> shape = {Vec2(0, 0), Vec2(0, 2), Vec2(1, 2),
                                     Vec2(1, 1), Vec2(2, 1), Vec2(2, 0)};
    const Profile p = Profile::polygon(shape);
    EXPECT_NEAR(capArea(p), 3.0, 1e-12);
    EXPECT_EQ(p.capTriangles().size(), 12u);
}

TEST(Profile, BadProfilesAreRefusedWithAReason)
{
    EXPECT_THROW(Profile::circle(0.0, 16), InvalidArgument);
    EXPECT_THROW(Profile::circle(0.1, 2), InvalidArgument);
    EXPECT_THROW(Profile::ellipse(0.1, -1, 8), InvalidArgument);
    EXPECT_THROW(Profile::roundedRectangle(0.04, 0.02, 0.011, 4), InvalidArgument);
    EXPECT_THROW(Profile::polygon({Vec2(0, 0), Vec2(1, 0)}), InvalidArgument);
    EXPECT_THROW(Profile::polygon({Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)}), InvalidArgument)
        << "zero area";
    try {
        Profile::polygon({Vec2(0, 0), Vec2(2, 2), Vec2(2, 0), Vec2(0, 1)}); // a bow tie
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("cross"), std::string::npos) << e.what();
    }
}
