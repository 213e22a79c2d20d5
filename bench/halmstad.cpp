#include "halmstad.h"

#include "map_file.h"

#include <multires_map_merge/GridImage.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <Eigen/Sparse>

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

std::vector<Similarity2D> HalmstadData::jointlyToFirst(const std::vector<std::string>& maps) const
{
	// Map k's pixels z go to the first map's as a_k·z + b_k (complex a, b:
	// four unknowns, linear); each correspondence (s of src, d of dst) asks
	// a_src·s + b_src = a_dst·d + b_dst. The first map is the identity.
	const size_t n = maps.size();
	std::vector<Eigen::Triplet<double>> a;
	std::vector<double> rhs;
	auto add = [&](size_t map, const Eigen::Vector2d& z, double sign, size_t row) {
		if (map == 0)  // fixed: the identity moves to the right-hand side
		{
			rhs[row] -= sign * z.x(), rhs[row + 1] -= sign * z.y();
			return;
		}
		const int c = int(4 * (map - 1));
		a.emplace_back(int(row), c, sign * z.x()), a.emplace_back(int(row), c + 1, -sign * z.y());
		a.emplace_back(int(row), c + 2, sign);
		a.emplace_back(int(row + 1), c, sign * z.y()), a.emplace_back(int(row + 1), c + 1, sign * z.x());
		a.emplace_back(int(row + 1), c + 3, sign);
	};
	for (size_t i = 0; i < n; ++i)
		for (size_t j = i + 1; j < n; ++j)
			if (const HalmstadPair* p = pair(maps[i], maps[j]))
				for (const auto& [s, d] : p->inliers)
				{
					const size_t row = rhs.size();
					rhs.resize(row + 2, 0.0);
					add(i, s, +1, row), add(j, d, -1, row);
				}
	Eigen::SparseMatrix<double> m(int(rhs.size()), int(4 * (n - 1)));
	m.setFromTriplets(a.begin(), a.end());
	const Eigen::SparseMatrix<double> normal = m.transpose() * m;
	Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
	const Eigen::VectorXd x = solver.solve(m.transpose() * Eigen::Map<const Eigen::VectorXd>(rhs.data(), rhs.size()));
	if (solver.info() != Eigen::Success) throw std::runtime_error("the annotations do not connect every map");
	std::vector<Similarity2D> out{Similarity2D()};
	for (size_t k = 1; k < n; ++k)
	{
		const double ar = x[4 * (k - 1)], ai = x[4 * (k - 1) + 1];
		out.emplace_back(std::hypot(ar, ai), std::atan2(ai, ar), Eigen::Vector2d(x[4 * (k - 1) + 2], x[4 * (k - 1) + 3]));
	}
	return out;
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
	writeMapServerYaml(path, fs::absolute(png(map)).string(), kHalmstadResolution, 0, 0, !isSensorMap(map));
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
	writeMapServerYaml(yaml, fs::path(pgm).filename().string(), kHalmstadResolution);
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

namespace
{
/** The pixels of a map's occupied cells (u, v from the top). */
std::vector<Eigen::Vector2d> occupiedPx(const GridInFrame& map)
{
	std::vector<cv::Point> occupied;
	cv::findNonZero(toClassImage(map.grid) == kOccupied, occupied);
	std::vector<Eigen::Vector2d> out;
	const int rows = static_cast<int>(map.grid.getSizeY());
	for (const auto& c : occupied) out.emplace_back(c.x, rows - 1 - c.y);  // class images have y up
	return out;
}
}  // namespace

double meanDisplacementPx(const Similarity2D& est, const Similarity2D& truth_px, const GridInFrame& other, int ref_rows)
{
	return meanDisplacementPx(est, truth_px, occupiedPx(other), static_cast<int>(other.grid.getSizeY()), ref_rows);
}

double meanDisplacementPx(
	const Similarity2D& est, const Similarity2D& truth_px, const std::vector<Eigen::Vector2d>& src_px, int src_rows,
	int ref_rows)
{
	if (!est.isFinite() || src_px.empty()) return NAN;
	double sum = 0;
	for (const auto& px : src_px) sum += (metricToPx(est(pxToMetric(px, src_rows)), ref_rows) - truth_px(px)).norm();
	return sum / src_px.size();
}

double annotationDisagreementPx(
	const HalmstadData& data, const std::vector<std::string>& maps, const std::vector<GridInFrame>& loaded)
{
	std::vector<double> disagreement;
	for (size_t k = 1; k < maps.size(); ++k)
	{
		const HalmstadPair* direct = data.pair(maps[k], maps[0]);
		if (!direct) continue;
		const std::vector<Eigen::Vector2d> px = occupiedPx(loaded[k]);
		for (size_t j = 1; j < maps.size(); ++j)
		{
			const HalmstadPair *to_j = data.pair(maps[k], maps[j]), *j_to_ref = data.pair(maps[j], maps[0]);
			if (j == k || !to_j || !j_to_ref || px.empty()) continue;
			const Similarity2D chain = j_to_ref->src_to_dst_px.compose(to_j->src_to_dst_px);
			double sum = 0;
			for (const auto& p : px) sum += (chain(p) - direct->src_to_dst_px(p)).norm();
			disagreement.push_back(sum / px.size());
		}
	}
	return median(disagreement);
}

HalmstadOutcome judge(const Similarity2D& est, const HalmstadPair& p, const GridInFrame& other, int ref_rows)
{
	HalmstadOutcome o;
	if (!est.isFinite()) return o;
	const int src_rows = static_cast<int>(other.grid.getSizeY());
	o.mean_displacement_px = meanDisplacementPx(est, p.src_to_dst_px, other, ref_rows);
	double se = 0;
	for (const auto& [s, d] : p.inliers)
		se += (metricToPx(est(pxToMetric(s, src_rows)), ref_rows) - d).squaredNorm();
	if (!p.inliers.empty()) o.corr_rms_px = std::sqrt(se / p.inliers.size());
	o.right = o.mean_displacement_px <= kRightPx && o.corr_rms_px <= std::max(2 * p.rms_px, kRightPx);
	return o;
}

}  // namespace multires_bench
