#include "test_util.h"

#include <numbers>

using namespace chaintube;
using namespace chaintube::test;

TEST(Material, DeflectionAngleFromMinBendRadiusMatchesThePolylineBendRadius)
{
    // R = l / (2 sin(θ/2)): reference values from chaintube-model.md.
    EXPECT_NEAR(bendRadiusOfTurn(1.0, 20 * kDegree), 2.88, 0.005);
    EXPECT_NEAR(bendRadiusOfTurn(1.0, 40 * kDegree), 1.46, 0.005);
    EXPECT_NEAR(bendRadiusOfTurn(1.0, 60 * kDegree), 1.00, 1e-12);
    for (double l : {0.001, 0.01, 0.1}) {
        const double theta = jointDeflectionLimit(BendLimit::minBendRadius(0.25), l);
        EXPECT_NEAR(bendRadiusOfTurn(l, theta), 0.25, 1e-12) << l;
    }
}

TEST(Material, SegmentsLongerThanTheBendDiameterAreUnlimited)
{
    EXPECT_EQ(jointDeflectionLimit(BendLimit::minBendRadius(0.1), 0.2), std::numbers::pi);
    EXPECT_EQ(jointDeflectionLimit(BendLimit::minBendRadius(0.0), 0.01), std::numbers::pi);
    EXPECT_EQ(jointDeflectionLimit(BendLimit::deflectionAngle(0.5), 123.0), 0.5);
}

TEST(Material, HalvingTheSegmentLengthHalvesTheJointAngleForARadiusButNotForAnAngle)
{
    const BendLimit radius = BendLimit::minBendRadius(0.2);
    const BendLimit angle = BendLimit::deflectionAngle(30 * kDegree);
    EXPECT_NEAR(jointDeflectionLimit(radius, 0.01) / jointDeflectionLimit(radius, 0.02), 0.5, 1e-3);
    EXPECT_EQ(jointDeflectionLimit(angle, 0.01), jointDeflectionLimit(angle, 0.02));
}

TEST(Material, ValidateNamesTheField)
{
    Material m;
    m.expansionCoefficient = -0.1;
    EXPECT_THROW(m.validate(), InvalidArgument);
    m.expansionCoefficient = 0.39;
    m.bendLimit.kind = BendLimit::Kind::DeflectionAngle;
    m.bendLimit.value = 4.0;
    try {
        m.validate();
        FAIL();
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("deflectionAngle"), std::string::npos);
    }
}
