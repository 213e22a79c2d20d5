#pragma once
// The Halmstad Robot Maps (../shared/data/halmstad, SOURCES.md §5): real
// sensor maps of four sites, each made in a separate session, with annotated
// correspondences and a fitted similarity per ordered pair. Shared by the
// benchmark ("Real independent maps") and the tests.
//
// The PNGs state no cell size: they are fed as map_server files at 0.05 m
// (0 occupied, 127 unknown, 255 free; a yaml beside the run pointing at the
// PNG), as a user would. The annotation lives in image pixels (u = column,
// v = row from the top); a map_server map with origin 0 puts pixel (u, v)'s
// centre at ((u + ½)·r, (H − v − ½)·r).

#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/Similarity2D.h>

#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace multires_bench
{
using multires_map_merge::GridInFrame;
using multires_map_merge::Similarity2D;

constexpr double kHalmstadResolution = 0.05;

/** Calibration sites (the decision may be tuned on them) and acceptance
 * sites (only reported: never tune on them). */
inline bool isCalibrationSite(const std::string& site) { return site == "E5" || site == "HIH"; }

/** The site a map of the data set belongs to: E5_01 and E5_layout → E5. */
std::string siteOf(const std::string& map);

struct HalmstadPair
{
	std::string site, src, dst;  //!< maps E5_01 …; OTHER = src, REF = dst
	Similarity2D src_to_dst_px;  //!< the annotation's fitted similarity, image pixels
	double rms_px = 0;  //!< the fit's own inlier residual
	std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> inliers;  //!< (src px, dst px)
};

struct HalmstadOutcome
{
	double mean_displacement_px = NAN;  //!< OTHER's occupied pixels, estimate vs annotation
	double corr_rms_px = NAN;  //!< the annotated inlier correspondences under the estimate
	bool right = false;  //!< both within the issue's bounds
};

/** Aligned pairs counted: merged right, refused, merged wrong. */
struct PairTally
{
	size_t pairs = 0, right = 0, refused = 0, wrong = 0;
	void add(bool merged, bool right_by_truth)
	{
		++pairs;
		if (!merged)
			++refused;
		else if (right_by_truth)
			++right;
		else
			++wrong;
	}
};

class HalmstadData
{
   public:
	/** Reads gt_similarity.csv and gt_correspondences.csv.gz under `root`;
	 * throws std::runtime_error naming the file when they are missing. */
	explicit HalmstadData(const std::string& root);

	std::vector<std::string> sites() const { return {"E5", "F5", "HIH", "KPT4A"}; }
	/** The site's floor plan (its `layout` PNG) as a map name: E5_layout. */
	static std::string floorPlan(const std::string& site) { return site + "_layout"; }
	/** The sensor maps of a site, sorted (E5_01 …). */
	std::vector<std::string> sensorMaps(const std::string& site) const;
	/** The annotated ordered pair src → dst, or nullptr. */
	const HalmstadPair* pair(const std::string& src, const std::string& dst) const;
	/** Each of `maps` placed in the first one's pixels from every annotated
	 * correspondence among them at once (linear least squares over the
	 * similarities, the first fixed): an annotation consistent around every
	 * cycle. One pair's own fit and its composition through a third map
	 * differ by a median 5–18 px on E5 and F5 (sensor maps bend, a pair has
	 * 14–27 correspondences); a fleet, placed from many pairs, is judged
	 * against this as well as against each pair's fit. */
	std::vector<Similarity2D> jointlyToFirst(const std::vector<std::string>& maps) const;
	/** Every unordered sensor-to-sensor pair of a site once (src < dst). */
	std::vector<HalmstadPair> unorderedPairs(const std::string& site) const;

	/** A sensor map's PNG, or a floor plan's (RGBA: transparent outside). */
	std::string png(const std::string& map) const;
	/** A map_server yaml for `map` at 0.05 m in `dir` (written once). */
	std::string yaml(const std::string& map, const std::string& dir) const;

   private:
	std::string root_;
	std::map<std::pair<std::string, std::string>, HalmstadPair> pairs_;
};

/** The sensor map's PNG (0 occupied, 127 unknown, 255 free) recorded with
 * cells `factor` times larger (a coarse cell occupied if any fine cell is,
 * else free if any is), as a map_server file in `dir` stated at 0.05 m:
 * wrong metadata, as a coarser robot's map read at a fine map's resolution. */
std::string coarserYaml(const HalmstadData& data, const std::string& map, double factor, const std::string& dir);

/** The fine map's frame into its coarser recording's (both read at 0.05 m,
 * origin 0): what turns a transform of the coarse map into the fine one's. */
Similarity2D fineToCoarse(double factor, int fine_rows, int coarse_rows);

/** The median of the finite values (NaN if none). */
double median(std::vector<double> v);

/** A candidate's transform of cells (REF ← OTHER) between the maps' frames. */
Similarity2D candidateMetric(const GridInFrame& ref, const Similarity2D& cells, const GridInFrame& other);

/** Mean distance of `other`'s occupied pixels between where `est` (between
 * the maps' frames) and `truth_px` (image pixels) put them, px of REF. */
double meanDisplacementPx(const Similarity2D& est, const Similarity2D& truth_px, const GridInFrame& other, int ref_rows);
/** The same over `src_px`, pixels of a source image of `src_rows` rows
 * whose frame is the map frame `est` starts from. */
double meanDisplacementPx(
	const Similarity2D& est, const Similarity2D& truth_px, const std::vector<Eigen::Vector2d>& src_px, int src_rows,
	int ref_rows);

/** How much the annotations disagree among themselves about where `maps[k]`
 * lies in `maps[0]` (k ≥ 1): the mean distance over its occupied pixels
 * between the pair's annotated fit and the composition of the fits through
 * each third map j; the median over every k and j. */
double annotationDisagreementPx(const HalmstadData& data, const std::vector<std::string>& maps,
	const std::vector<GridInFrame>& loaded);

/** A placement is right within this mean displacement of OTHER's occupied
 * pixels from the annotation's [px of 5 cm]: 2 m, what separate SLAM runs
 * of one building bend apart. */
constexpr double kRightPx = 40;

/** A candidate's displacement against the annotation [px] and whether that
 * is right (cells of REF ← cells of OTHER as aligned; never right for a
 * pair of different sites). */
using CandidateError = std::function<std::pair<double, bool>(const Similarity2D& cells)>;

/** Judges a transform between the maps' frames (x_ref = est(x_other); REF =
 * dst, OTHER = src, both loaded from the yamls) against the annotation:
 * mean displacement ≤ kRightPx and correspondence RMS ≤ max(2·rms_px, kRightPx). */
HalmstadOutcome judge(const Similarity2D& est, const HalmstadPair& p, const GridInFrame& other, int ref_rows);

/** The annotation as a transform between the maps' frames (metres), for maps
 * of `src_rows` and `dst_rows` pixel rows. */
Similarity2D truthBetweenMapFrames(const HalmstadPair& p, int src_rows, int dst_rows);

}  // namespace multires_bench
