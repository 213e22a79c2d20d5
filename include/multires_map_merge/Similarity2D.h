#pragma once
// A 2-D similarity q = s·R(yaw)·p + t: the one type every transform in this
// package travels as (cell↔cell, cell↔metric, metric↔metric).

#include <Eigen/Core>
#include <cmath>
#include <iosfwd>

namespace multires_map_merge
{
struct Similarity2D
{
	double scale = 1.0;
	double yaw = 0.0;  //!< radians
	Eigen::Vector2d t = Eigen::Vector2d::Zero();

	Similarity2D() = default;
	Similarity2D(double s, double yaw_, const Eigen::Vector2d& t_)
		: scale(s), yaw(yaw_), t(t_)
	{
	}

	/** The linear part s·R. */
	Eigen::Matrix2d linear() const;
	Eigen::Vector2d apply(const Eigen::Vector2d& p) const
	{
		return linear() * p + t;
	}
	Eigen::Vector2d operator()(const Eigen::Vector2d& p) const
	{
		return apply(p);
	}

	/** (*this ∘ inner)(p) = this(inner(p)). */
	Similarity2D compose(const Similarity2D& inner) const;
	Similarity2D inverse() const;

	/** From a 2x3 [sR | t] or 3x3 homogeneous matrix; the linear part must be a
	 * scaled rotation (no reflection, no shear). */
	static Similarity2D fromMatrix(const Eigen::Matrix<double, 2, 3>& m);
	static Similarity2D fromMatrix(const Eigen::Matrix3d& m);
	Eigen::Matrix3d matrix() const;

	/** Maps continuous cell coordinates (cell (i,j) centre at (i,j), the same
	 * convention as OpenCV pixel centres) of a grid with the given cell size and
	 * lower-left corner to metric coordinates. */
	static Similarity2D cellToMetric(double resolution, double x_min, double y_min);

	bool isFinite() const
	{
		return std::isfinite(scale) && std::isfinite(yaw) && t.allFinite();
	}
};

/** Wraps an angle to (-pi, pi]. */
double wrapToPi(double a);

std::ostream& operator<<(std::ostream& o, const Similarity2D& s);

}  // namespace multires_map_merge
