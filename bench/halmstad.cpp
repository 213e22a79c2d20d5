#include "halmstad.h"

#include <multires_map_merge/GridImage.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

namespace
{
std::vector<std::string> csvFields(const std::string& line)
{
	std::vector<std::string> f;
	std::stringstream s(line);
	for (std::string x; std::getline(s, x, ',');) f.push_back(x);
	return f;
}

std::string readGz(const std::string& path)
{
	mrpt::io::CFileGZInputStream in;
	if (!in.open(path)) throw std::runtime_error("'" + path + "': cannot open");
	std::string text;
	char buf[65536];
	for (size_t n; (n = in.Read(buf, sizeof buf)) > 0;) text.append(buf, n);
	return text;
}

bool isSensorMap(const std::string& map) { return map.find("layout") == std::string::npos; }

// Pixel (u, v) (v from the top) → metres of a map_server map with origin 0.
Eigen::Vector2d pxToMetric(const Eigen::Vector2d& px, int rows)
{
	return {(px.x() + 0.5) * kHalmstadResolution, (rows - px.y() - 0.5) * kHalmstadResolution};
}
Eigen::Vector2d metricToPx(const Eigen::Vector2d& m, int rows)
{
	return {m.x() / kHalmstadResolution - 0.5, rows - 0.5 - m.y() / kHalmstadResolution};
}
}  // namespace

std::string siteOf(const std::string& map) { return map.substr(0, map.find('_')); }

HalmstadData::HalmstadData(const std::string& root) : root_(root)
{
	const std::string sim = root + "/gt_similarity.csv";
	std::ifstream in(sim);
	if (!in) throw std::runtime_error("'" + sim + "': cannot open (is ../shared/data beside the repo?)");
	for (std::string line; std::getline(in, line);)
	{
		if (line.empty() || line[0] == '#' || line.rfind("env,", 0) == 0) continue;
		const auto f = csvFields(line);  // env,src,dst,n_corr,n_inliers,scale,theta_deg,tx_px,ty_px,rms_px,max_px
		if (f.size() < 10) continue;
		HalmstadPair p;
		p.site = f[0], p.src = f[1], p.dst = f[2];
		p.src_to_dst_px = Similarity2D(std::stod(f[5]), std::stod(f[6]) * M_PI / 180, {std::stod(f[7]), std::stod(f[8])});
		p.rms_px = std::stod(f[9]);
		pairs_[{p.src, p.dst}] = p;
	}
	std::stringstream corr(readGz(root + "/gt_correspondences.csv.gz"));
	for (std::string line; std::getline(corr, line);)
	{
		if (line.empty() || line[0] == '#' || line.rfind("src,", 0) == 0) continue;
		const auto f = csvFields(line);  // src,dst,u_src,v_src,u_dst,v_dst,inlier
		if (f.size() < 7 || f[6] != "1") continue;
		auto it = pairs_.find({f[0], f[1]});
		if (it == pairs_.end()) continue;
		it->second.inliers.push_back(
			{{std::stod(f[2]), std::stod(f[3])}, {std::stod(f[4]), std::stod(f[5])}});
	}
	if (pairs_.empty()) throw std::runtime_error("'" + sim + "': no pairs");
}

std::vector<std::string> HalmstadData::sensorMaps(const std::string& site) const
{
	std::vector<std::string> maps;
	for (const auto& e : fs::directory_iterator(root_ + "/maps/" + site + "/pseudo_occupancy"))
		if (e.path().extension() == ".png") maps.push_back(e.path().stem().string());
	std::sort(maps.begin(), maps.end());
	return maps;
}

const HalmstadPair* HalmstadData::pair(const std::string& src, const std::string& dst) const
{
	auto it = pairs_.find({src, dst});
	return it == pairs_.end() ? nullptr : &it->second;
}

std::vector<HalmstadPair> HalmstadData::unorderedPairs(const std::string& site) const
{
	std::vector<HalmstadPair> out;
	for (const auto& [key, p] : pairs_)
		if (p.site == site && key.first < key.second && isSensorMap(p.src) && isSensorMap(p.dst)) out.push_back(p);
	return out;
}

std::string HalmstadData::png(const std::string& map) const
{
	return root_ + "/maps/" + siteOf(map) + (isSensorMap(map) ? "/pseudo_occupancy/" : "/layout/") + map + ".png";
}

std::string HalmstadData::yaml(const std::string& map, const std::string& dir) const
{
	fs::create_directories(dir);
	const std::string path = dir + "/" + map + ".yaml";
	// Written each time: what it says is the benchmark's, not a stale file's.
	std::ofstream(path) << "image: " << fs::absolute(png(map)).string() << "\nresolution: " << kHalmstadResolution
						<< "\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
						<< (isSensorMap(map) ? "" : "floor_plan: true\n");
	return path;
}

/** The sensor map's PNG (0 occupied, 127 unknown, 255 free) recorded with
 * cells `factor` times larger, as a map_server file stated at 0.05 m. */
std::string coarserYaml(const HalmstadData& data, const std::string& map, double factor, const std::string& dir)
{
	std::ostringstream name;
	name << map << "_x" << factor;
	const std::string yaml = dir + "/" + name.str() + ".yaml";
	if (fs::exists(yaml)) return yaml;
	const cv::Mat fine = cv::imread(data.png(map), cv::IMREAD_GRAYSCALE);
	if (fine.empty()) throw std::runtime_error("'" + data.png(map) + "': cannot read");
	const int rows = int(std::ceil(fine.rows / factor)), cols = int(std::ceil(fine.cols / factor));
	cv::Mat occupied(rows, cols, CV_8U, cv::Scalar(0)), free(rows, cols, CV_8U, cv::Scalar(0));
	for (int v = 0; v < fine.rows; ++v)
		for (int u = 0; u < fine.cols; ++u)
		{
			// Coarse cell j spans fine cells [j·factor, (j+1)·factor).
			const int cv = std::min(rows - 1, int(v / factor)), cu = std::min(cols - 1, int(u / factor));
			const uint8_t p = fine.at<uint8_t>(v, u);
			if (p < 64) occupied.at<uint8_t>(cv, cu) = 1;
			else if (p > 191) free.at<uint8_t>(cv, cu) = 1;
		}
	cv::Mat coarse(rows, cols, CV_8U, cv::Scalar(127));
	coarse.setTo(255, free);
	coarse.setTo(0, occupied);
	fs::create_directories(dir);
	const std::string pgm = dir + "/" + name.str() + ".pgm";
	if (!cv::imwrite(pgm, coarse)) throw std::runtime_error("'" + pgm + "': cannot write");
	std::ofstream(yaml) << "image: " << fs::path(pgm).filename().string() << "\nresolution: " << kHalmstadResolution
						<< "\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
	return yaml;
}

/** The fine map's frame into the coarse map's (both read at 0.05 m, origin
 * 0, +y up from the bottom row): x / factor, and y measured from the top
 * edge, which both share. */
Similarity2D fineToCoarse(double factor, int fine_rows, int coarse_rows)
{
	const double r = kHalmstadResolution;
	return Similarity2D(1 / factor, 0, {0, (coarse_rows - fine_rows / factor) * r});
}

double median(std::vector<double> v)
{
	v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
	if (v.empty()) return NAN;
	std::sort(v.begin(), v.end());
	return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

Similarity2D truthBetweenMapFrames(const HalmstadPair& p, int src_rows, int dst_rows)
{
	// Two points fix a similarity; the pixel↔metre maps flip y, which turns
	// the pixel-frame angle θ into −θ.
	const Eigen::Vector2d a(0, 0), b(1000, 0);
	const Eigen::Vector2d ma = pxToMetric(a, src_rows), mb = pxToMetric(b, src_rows);
	const Eigen::Vector2d qa = pxToMetric(p.src_to_dst_px(a), dst_rows), qb = pxToMetric(p.src_to_dst_px(b), dst_rows);
	const Eigen::Vector2d d_src = mb - ma, d_dst = qb - qa;
	const double scale = d_dst.norm() / d_src.norm();
	const double yaw = std::atan2(d_dst.y(), d_dst.x()) - std::atan2(d_src.y(), d_src.x());
	Similarity2D t(scale, wrapToPi(yaw), {0, 0});
	t.t = qa - t.apply(ma);
	return t;
}

Similarity2D candidateMetric(const GridInFrame& ref, const Similarity2D& cells, const GridInFrame& other)
{
	return betweenMapFrames(ref, cellToMetric(ref.grid).compose(cells).compose(cellToMetric(other.grid).inverse()), other);
}

HalmstadOutcome judge(const Similarity2D& est, const HalmstadPair& p, const GridInFrame& other, int ref_rows)
{
	HalmstadOutcome o;
	if (!est.isFinite()) return o;
	const int src_rows = static_cast<int>(other.grid.getSizeY());
	std::vector<cv::Point> occupied;
	cv::findNonZero(toClassImage(other.grid) == kOccupied, occupied);
	double sum = 0;
	size_t n = 0;
	for (const auto& c : occupied)
	{
		// Class images have row = cy (y up): pixel v = rows − 1 − cy.
		const Eigen::Vector2d px(c.x, src_rows - 1 - c.y);
		const Eigen::Vector2d q_est = metricToPx(est(pxToMetric(px, src_rows)), ref_rows);
		sum += (q_est - p.src_to_dst_px(px)).norm(), ++n;
	}
	if (n) o.mean_displacement_px = sum / n;
	double se = 0;
	for (const auto& [s, d] : p.inliers)
		se += (metricToPx(est(pxToMetric(s, src_rows)), ref_rows) - d).squaredNorm();
	if (!p.inliers.empty()) o.corr_rms_px = std::sqrt(se / p.inliers.size());
	o.right = o.mean_displacement_px <= 40 && o.corr_rms_px <= std::max(2 * p.rms_px, 40.0);
	return o;
}

}  // namespace multires_bench
