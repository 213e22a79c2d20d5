#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/obs/carmen_log_tools.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDF.h>

#include <opencv2/imgproc.hpp>

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
	if (hasSuffix(path, ".simplemap") || hasSuffix(path, ".simplemap.gz"))
		return loadSimplemapScans(path);
	if (hasSuffix(path, ".log") || hasSuffix(path, ".log.gz")) return loadCarmenScans(path);
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

GridInFrame renderGridOffLattice(
	const ScanSequence& scans, size_t begin, size_t end, double resolution, const mrpt::poses::CPose2D& frame,
	double dx, double dy, float max_range)
{
	// A point p of the shifted frame is p + (dx, dy) in `frame`.
	return {renderGrid(scans, begin, end, resolution, frame + mrpt::poses::CPose2D(dx, dy, 0), max_range),
			Similarity2D(1, 0, {dx, dy})};
}

GroundTruthPair makeGroundTruthPair(const ScanSequence& scans, const PairSpec& spec)
{
	const size_t n = scans.size();
	const auto at = [n](double f) {
		return static_cast<size_t>(std::lround(std::clamp(f, 0.0, 1.0) * static_cast<double>(n)));
	};
	GroundTruthPair p;
	p.ref = renderGrid(scans, 0, at(spec.ref_end), spec.ref_resolution, {}, spec.max_range,
		spec.free_update_certainty);
	p.other = renderGrid(
		scans, at(spec.other_begin), n, spec.other_resolution, spec.other_frame, spec.max_range,
		spec.free_update_certainty);
	p.other_to_ref = Similarity2D(
		1.0, spec.other_frame.phi(), Eigen::Vector2d(spec.other_frame.x(), spec.other_frame.y()));
	return p;
}

Similarity2D GroundTruthPair::otherCellsToRefCells() const
{
	return cellToMetric(ref).inverse().compose(other_to_ref).compose(cellToMetric(other));
}

COccupancyGridMap2D withStatedResolution(const COccupancyGridMap2D& grid, double res)
{
	const int w = static_cast<int>(grid.getSizeX()), h = static_cast<int>(grid.getSizeY());
	COccupancyGridMap2D out;
	out.setSize(
		grid.getXMin(), grid.getXMin() + static_cast<float>(w * res), grid.getYMin(),
		grid.getYMin() + static_cast<float>(h * res), static_cast<float>(res));
	const int w2 = std::min<int>(w, out.getSizeX()), h2 = std::min<int>(h, out.getSizeY());
	for (int cy = 0; cy < h2; ++cy)
		for (int cx = 0; cx < w2; ++cx) out.setCell(cx, cy, grid.getCell(cx, cy));
	return out;
}

std::vector<Eigen::Vector2d> occupiedPointsInMapFrame(const GridInFrame& map)
{
	std::vector<cv::Point> cells;
	cv::findNonZero(toClassImage(map.grid) == kOccupied, cells);
	const Similarity2D to_frame = map.cellToMapFrame();
	std::vector<Eigen::Vector2d> pts;
	pts.reserve(cells.size());
	for (const auto& c : cells) pts.push_back(to_frame(Eigen::Vector2d(c.x, c.y)));
	return pts;
}

double pointRmse(
	const Similarity2D& estimate, const Similarity2D& truth,
	const std::vector<Eigen::Vector2d>& points)
{
	if (points.empty()) return 0;
	double sum = 0;
	for (const auto& p : points) sum += (estimate(p) - truth(p)).squaredNorm();
	return std::sqrt(sum / static_cast<double>(points.size()));
}

void forgetSeenBy(GridInFrame& map, const Similarity2D& map_to_seen, const GridInFrame& seen, double margin_m)
{
	cv::Mat known = toClassImage(seen.grid) != kUnknown;
	const int margin = static_cast<int>(std::ceil(margin_m / seen.grid.getResolution()));
	cv::dilate(known, known, cv::Mat::ones(2 * margin + 1, 2 * margin + 1, CV_8UC1));
	const Similarity2D to_seen_cells = seen.cellToMapFrame().inverse().compose(map_to_seen).compose(map.cellToMapFrame());
	for (int y = 0; y < int(map.grid.getSizeY()); ++y)
		for (int x = 0; x < int(map.grid.getSizeX()); ++x)
		{
			const Eigen::Vector2d q = to_seen_cells(Eigen::Vector2d(x, y));
			const int qx = int(std::lround(q.x())), qy = int(std::lround(q.y()));
			if (qx >= 0 && qy >= 0 && qx < known.cols && qy < known.rows && known.at<uint8_t>(qy, qx))
				map.grid.setCell(x, y, 0.5f);
		}
}

}  // namespace multires_map_merge
