#include <multires_map_merge/Similarity2D.h>

#include <Eigen/Geometry>
#include <iomanip>
#include <ostream>

namespace multires_map_merge
{
Eigen::Matrix2d Similarity2D::linear() const
{
	return scale * Eigen::Rotation2Dd(yaw).toRotationMatrix();
}

Similarity2D Similarity2D::compose(const Similarity2D& inner) const
{
	return {scale * inner.scale, wrapToPi(yaw + inner.yaw), linear() * inner.t + t};
}

Similarity2D Similarity2D::inverse() const
{
	const Eigen::Matrix2d inv_linear =
		Eigen::Rotation2Dd(-yaw).toRotationMatrix() / scale;
	return {1.0 / scale, wrapToPi(-yaw), -inv_linear * t};
}

Similarity2D Similarity2D::fromMatrix(const Eigen::Matrix<double, 2, 3>& m)
{
	// For s·R the columns are (s·c, s·s') and (-s·s', s·c): the mean of the
	// two estimates is the least-squares scaled rotation.
	const double a = 0.5 * (m(0, 0) + m(1, 1));
	const double b = 0.5 * (m(1, 0) - m(0, 1));
	return {std::hypot(a, b), std::atan2(b, a), m.col(2)};
}

Similarity2D Similarity2D::fromMatrix(const Eigen::Matrix3d& m)
{
	return fromMatrix(Eigen::Matrix<double, 2, 3>(m.topRows<2>()));
}

Eigen::Matrix3d Similarity2D::matrix() const
{
	Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
	m.topLeftCorner<2, 2>() = linear();
	m.topRightCorner<2, 1>() = t;
	return m;
}

Similarity2D Similarity2D::cellToMetric(double resolution, double x_min, double y_min)
{
	// Cell i spans [x_min + i·res, x_min + (i+1)·res); its centre is at i.
	return {resolution, 0.0,
			Eigen::Vector2d(x_min + 0.5 * resolution, y_min + 0.5 * resolution)};
}

double wrapToPi(double a)
{
	a = std::remainder(a, 2.0 * M_PI);
	return a <= -M_PI ? a + 2.0 * M_PI : a;
}

std::ostream& operator<<(std::ostream& o, const Similarity2D& s)
{
	const auto f = o.flags();
	o << std::setprecision(6) << "{scale " << s.scale << ", yaw "
	  << s.yaw * 180.0 / M_PI << " deg, t (" << s.t.x() << ", " << s.t.y() << ")}";
	o.flags(f);
	return o;
}

}  // namespace multires_map_merge
