#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <mrpt/ros1bridge/map.h>

#include <cmath>
#include <sstream>

namespace multires_map_merge::ros1
{
namespace
{
[[noreturn]] void fail(const std::string& what, const std::string& why)
{
	throw InvalidGridMessage(what + ": " + why);
}
}  // namespace

Similarity2D originOf(const nav_msgs::OccupancyGrid& msg, const std::string& what)
{
	const auto& p = msg.info.origin.position;
	const auto& q = msg.info.origin.orientation;
	if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
		fail(what, "info.origin.position is not finite");
	if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w))
		fail(what, "info.origin.orientation is not finite");
	const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
	// A default-constructed Pose has the all-zero quaternion; publishers that
	// never set it mean "no rotation".
	if (norm == 0) return Similarity2D(1, 0, {p.x, p.y});
	// A tilted grid has no 2-D meaning.
	constexpr double kTilt = 1e-5;
	if (std::abs(q.x) > kTilt * norm || std::abs(q.y) > kTilt * norm)
		fail(what, "info.origin.orientation tilts the grid out of the x-y plane (only rotations about z are 2-D)");
	return Similarity2D(1, wrapToPi(2 * std::atan2(q.z, q.w)), {p.x, p.y});
}

GridInFrame gridFromMsg(const nav_msgs::OccupancyGrid& msg, const std::string& what)
{
	const auto& info = msg.info;
	if (info.width == 0 || info.height == 0)
	{
		std::ostringstream s;
		s << "empty grid (" << info.width << "x" << info.height << " cells)";
		fail(what, s.str());
	}
	const uint64_t cells = uint64_t(info.width) * uint64_t(info.height);
	if (msg.data.size() != cells)
	{
		std::ostringstream s;
		s << "data has " << msg.data.size() << " values but width x height = " << info.width << " x "
		  << info.height << " = " << cells;
		fail(what, s.str());
	}
	if (!std::isfinite(info.resolution) || !(info.resolution > 0))
	{
		std::ostringstream s;
		s << "resolution must be a finite number of metres > 0, not " << info.resolution;
		fail(what, s.str());
	}
	GridInFrame out;
	out.origin = originOf(msg, what);
	for (size_t i = 0; i < msg.data.size(); ++i)
	{
		const int v = msg.data[i];
		if (v < -1 || v > 100)
		{
			std::ostringstream s;
			s << "cell value " << v << " at row " << i / info.width << ", column " << i % info.width
			  << " is neither -1 (unknown) nor an occupancy 0..100";
			fail(what, s.str());
		}
	}

	// ros1bridge refuses rotated origins and places the grid at the origin's
	// position in float arithmetic; give it the origin frame instead.
	nav_msgs::OccupancyGrid local;
	local.info = info;
	local.info.origin = geometry_msgs::Pose();
	local.info.origin.orientation.w = 1;
	local.data = msg.data;
	try
	{
		if (!mrpt::ros1bridge::fromROS(local, out.grid))
			fail(what, "mrpt::ros1bridge::fromROS refused the grid");
	}
	catch (const InvalidGridMessage&)
	{
		throw;
	}
	catch (const std::exception& e)
	{
		const std::string why = e.what();
		fail(what, "cannot be converted: " + why.substr(0, why.find('\n')));
	}
	if (out.grid.getSizeX() != info.width || out.grid.getSizeY() != info.height)
	{
		std::ostringstream s;
		s << "converted to " << out.grid.getSizeX() << "x" << out.grid.getSizeY() << " cells instead of "
		  << info.width << "x" << info.height << " (resolution " << info.resolution << " too extreme)";
		fail(what, s.str());
	}
	return out;
}

nav_msgs::OccupancyGrid msgFromGrid(const GridInFrame& map, const std_msgs::Header& header)
{
	nav_msgs::OccupancyGrid msg;
	mrpt::ros1bridge::toROS(map.grid, msg, header);
	const Similarity2D& origin = map.origin;
	const Eigen::Vector2d corner = map.cornerInMapFrame();
	msg.info.map_load_time = header.stamp;
	msg.info.origin = geometry_msgs::Pose();
	msg.info.origin.position.x = corner.x();
	msg.info.origin.position.y = corner.y();
	msg.info.origin.orientation.z = std::sin(origin.yaw / 2);
	msg.info.origin.orientation.w = std::cos(origin.yaw / 2);
	return msg;
}

geometry_msgs::Pose2D pose2DOf(const Similarity2D& t)
{
	geometry_msgs::Pose2D p;
	p.x = t.t.x(), p.y = t.t.y(), p.theta = t.yaw;
	return p;
}

}  // namespace multires_map_merge::ros1
