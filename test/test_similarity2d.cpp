#include <multires_map_merge/Similarity2D.h>

#include <gtest/gtest.h>

using multires_map_merge::Similarity2D;

TEST(Similarity2D, ComposeAndInverseRoundTrip)
{
	const Similarity2D a(2.5, 0.7, {3, -4}), b(0.4, -2.9, {-1, 8});
	const Eigen::Vector2d p(1.25, -0.5);
	EXPECT_TRUE(a.compose(b)(p).isApprox(a(b(p)), 1e-12));
	EXPECT_TRUE(a.inverse()(a(p)).isApprox(p, 1e-12));
	const Similarity2D id = a.compose(a.inverse());
	EXPECT_NEAR(id.scale, 1, 1e-12);
	EXPECT_NEAR(id.yaw, 0, 1e-12);
	EXPECT_LT(id.t.norm(), 1e-12);
}

TEST(Similarity2D, FromMatrixRecoversParameters)
{
	const Similarity2D a(1.7, -2.2, {0.5, 9});
	const Similarity2D b = Similarity2D::fromMatrix(a.matrix());
	EXPECT_NEAR(b.scale, a.scale, 1e-12);
	EXPECT_NEAR(b.yaw, a.yaw, 1e-12);
	EXPECT_TRUE(b.t.isApprox(a.t));
}

TEST(Similarity2D, CellToMetricUsesCellCentres)
{
	// MRPT: cell cx spans [x_min + cx·res, x_min + (cx+1)·res).
	const auto m = Similarity2D::cellToMetric(0.05, -10, 2);
	EXPECT_TRUE(m(Eigen::Vector2d(0, 0)).isApprox(Eigen::Vector2d(-9.975, 2.025)));
	EXPECT_TRUE(m(Eigen::Vector2d(4, 2)).isApprox(Eigen::Vector2d(-9.775, 2.125)));
}

TEST(Similarity2D, WrapToPi)
{
	using multires_map_merge::wrapToPi;
	EXPECT_NEAR(wrapToPi(3 * M_PI / 2), -M_PI / 2, 1e-12);
	EXPECT_NEAR(wrapToPi(-3 * M_PI / 2), M_PI / 2, 1e-12);
	EXPECT_NEAR(wrapToPi(M_PI), M_PI, 1e-12);
	EXPECT_NEAR(wrapToPi(-M_PI), M_PI, 1e-12);
}
