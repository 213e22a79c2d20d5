#include <multires_map_merge/ScanLog.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/obs/carmen_log_tools.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/system/filesystem.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace multires_map_merge
{
using mrpt::maps::COccupancyGridMap2D;

namespace
{
std::string readMaybeGzipped(const std::string& path)
{
	// CFileGZInputStream reads plain files too.
	mrpt::io::CFileGZInputStream in;
	if (!in.open(path)) throw std::runtime_error("cannot open '" + path + "'");
	std::string content;
	char buf[1 << 16];
	for (size_t n; (n = in.Read(buf, sizeof(buf))) > 0;) content.append(buf, n);
	return content;
}
}  // namespace

ScanSequence loadSimplemapScans(const std::string& path)
{
	mrpt::maps::CSimpleMap sm;
	if (!sm.loadFromFile(path))
		throw std::runtime_error("cannot read simplemap '" + path + "'");
	ScanSequence out;
	for (size_t i = 0; i < sm.size(); ++i)
	{
		const auto [pose_pdf, sf] = sm.get(i);
		if (!pose_pdf || !sf) continue;
		auto scan = sf->getObservationByClass<mrpt::obs::CObservation2DRangeScan>();
		if (!scan) continue;
		const mrpt::poses::CPose3D p = pose_pdf->getMeanVal();
		out.push_back({mrpt::poses::CPose2D(p), scan});
	}
	if (out.empty()) throw std::runtime_error("simplemap '" + path + "' holds no 2-D laser scans");
	return out;
}

ScanSequence loadCarmenScans(const std::string& path)
{
	std::istringstream in(readMaybeGzipped(path));
	ScanSequence out;
	std::vector<mrpt::obs::CObservation::Ptr> obs;
	const auto t0 = mrpt::Clock::now();
	// Lines come in log order; the corrected pose is the odometry MRPT reads
	// from each FLASER line, so scans are ordered by line, not by timestamp.
	while (mrpt::obs::carmen_log_parse_line(in, obs, t0))
	{
		mrpt::obs::CObservation2DRangeScan::Ptr scan;
		mrpt::obs::CObservationOdometry::Ptr odo;
		for (const auto& o : obs)
		{
			if (auto s = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(o)) scan = s;
			if (auto d = std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(o)) odo = d;
		}
		if (!scan || !odo) continue;
		// FLASER scans span 180° (SOURCES.md of the data; CARMEN's front laser).
		// MRPT's parser guesses 90° for 180-beam lines, which smears such maps.
		// CARMEN's beam i sits at -90° + i·180°/(n-1) for n odd (181, 361) and
		// at -90° + i·180°/n for n even (180, 360); MRPT spreads n beams over
		// the aperture end to end, centred on the sensor yaw.
		const size_t n = scan->getScanSize();
		if (n >= 2)
		{
			if (n % 2 == 1)
				scan->aperture = static_cast<float>(M_PI);
			else
			{
				scan->aperture = static_cast<float>(M_PI * (n - 1) / n);
				scan->sensorPose.setYawPitchRoll(-M_PI / (2.0 * n), 0, 0);
			}
		}
		out.push_back({odo->odometry, scan});
	}
	if (out.empty()) throw std::runtime_error("CARMEN log '" + path + "' holds no FLASER scans");
	return out;
}

ScanSequence loadScans(const std::string& path)
{
	const std::string extension = mrpt::system::extractFileExtension(path, true);  // under a .gz
	if (extension == "simplemap") return loadSimplemapScans(path);
	if (extension == "log") return loadCarmenScans(path);
	throw std::runtime_error(
		"'" + path + "': expected a .simplemap(.gz) or a CARMEN .log(.gz)");
}

COccupancyGridMap2D renderGrid(
	const ScanSequence& scans, size_t begin, size_t end, double resolution,
	const mrpt::poses::CPose2D& frame, float max_range, float free_update_certainty)
{
	if (!(resolution > 0)) throw std::invalid_argument("renderGrid: resolution must be > 0");
	// The grid grows as scans are inserted; start small around the first pose.
	COccupancyGridMap2D grid(-1.0f, 1.0f, -1.0f, 1.0f, static_cast<float>(resolution));
	grid.insertionOptions.maxDistanceInsertion = max_range;
	grid.insertionOptions.maxFreenessUpdateCertainty = free_update_certainty;
	const mrpt::poses::CPose2D to_frame = -frame;
	for (size_t i = begin; i < std::min(end, scans.size()); ++i)
	{
		const mrpt::poses::CPose2D pose = to_frame + scans[i].robot_pose;
		grid.insertObservation(*scans[i].scan, mrpt::poses::CPose3D(pose));
	}
	return grid;
}

}  // namespace multires_map_merge
