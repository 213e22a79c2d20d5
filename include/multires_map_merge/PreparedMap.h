#pragma once
// One map as the aligner sees it (its class image, feature pyramid, edge
// points and occupancy field), and the refinement of a transform between two
// such maps. Preparing is most of an alignment's time, and a map in a fleet
// takes part in several pairs: prepare it once, align it in each.

#include <multires_map_merge/FeatureHypotheses.h>
#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/MapAgreement.h>
#include <multires_map_merge/PointKDTree.h>
#include <multires_map_merge/Similarity2D.h>
#include <multires_map_merge/TsICP.h>

#include <opencv2/core.hpp>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace multires_map_merge
{
class MapWalls;  // StructureHypotheses.h

/** A value made from a map when first asked and kept with it, by whichever
 * thread asks first. A copy of the map starts without one: it may be
 * changed before it is asked. */
template <class T>
class OnceCache
{
   public:
	OnceCache() = default;
	OnceCache(const OnceCache&) {}
	OnceCache& operator=(const OnceCache&)
	{
		once_ = std::make_shared<Once>();
		return *this;
	}
	template <class Make>
	const std::shared_ptr<const T>& get(Make make) const
	{
		std::call_once(once_->flag, [&] { once_->value = make(); });
		return once_->value;
	}

   private:
	struct Once
	{
		std::once_flag flag;
		std::shared_ptr<const T> value;
	};
	std::shared_ptr<Once> once_ = std::make_shared<Once>();  // a once_flag cannot be copied or moved
};

struct PreparedMap
{
	/** Why this map cannot be aligned, after "reference map " or "other
	 * map " ("" when it can): no structure, too small or too large. */
	std::string problem;
	MapKind kind = MapKind::Sensed;  //!< a floor plan's field claims only its walls
	double resolution = 0;  //!< as stated
	/** The prepared cells' (0, 0) is this cell of the grid it was prepared
	 * from: (0, 0), or with crop_to_known the corner of its known box
	 * widened by kKnownMargin (negative where that passes the grid's edge).
	 * Everything below is in prepared cells; the aligner's results are
	 * reported in the grids' (gridCells). */
	cv::Point grid_corner{0, 0};
	/** The prepared cells → the cells of the grid (a shift by grid_corner). */
	Similarity2D toGridCells() const { return Similarity2D(1, 0, Eigen::Vector2d(grid_corner.x, grid_corner.y)); }
	Similarity2D cell_to_metric;  //!< the prepared cells → the grid's metric frame
	cv::Mat classes;  //!< GridImage.h
	FeatureParams feature_params;  //!< those the features were extracted with
	std::vector<LevelFeatures> features;
	PointList edges;
	/** On `edges`, built once: every hypothesis's TsICP moves one map's
	 * edges, either map's (null with fewer than 3 edge points). */
	std::shared_ptr<const PointKDTree> edge_tree;
	/** The centroid of `edges` (cells): where a placement puts the map is
	 * told apart by where this lands. */
	Eigen::Vector2d wall_centroid{0, 0};
	OccupancyField field;
	std::map<std::string, double> stage_seconds;  //!< features, edges

	/** This map mirrored (mirroredMap), made when first asked and kept with
	 * it (as much memory again): the mirror check flips the reference, and a
	 * fleet's reference meets it in every pair. Safe to call from several
	 * threads. */
	std::shared_ptr<const PreparedMap> mirrored() const;
	/** Its walls as the structure search reads them (MapWalls), made when
	 * first asked and kept with it: a fleet's reference meets the same wall
	 * images in every pair. Safe to call from several threads. */
	const MapWalls& walls() const;
	OnceCache<PreparedMap> mirror_cache;
	OnceCache<MapWalls> walls_cache;
};
using PreparedMapPtr = std::shared_ptr<const PreparedMap>;

/** Cells of unknown kept around a map's known box when it is cropped
 * (crop_to_known): its outermost walls keep unknown beyond them, as edge
 * points, occupancy field and structure search see them in a padded grid. */
constexpr int kKnownMargin = 16;

/** The class image of a map's known part: its occupied and free cells' box
 * widened by `margin` cells of unknown (past the image's edge too), and that
 * box's corner in `classes`. An image with no known cell is kept whole. */
cv::Mat knownPart(const cv::Mat& classes, int margin, cv::Point& corner);

/** A transform between two prepared maps' cells (other → ref) as one between
 * their grids' cells, and back. */
Similarity2D gridCells(const PreparedMap& ref, const Similarity2D& prepared_cells, const PreparedMap& other);
Similarity2D preparedCells(const PreparedMap& ref, const Similarity2D& grid_cells, const PreparedMap& other);

/** Features, edge points and occupancy field of a map's `classes`, with its
 * `feature_params`. */
void describeMap(PreparedMap& map);

/** The map with its x axis flipped, described (the aligner's mirror check). */
PreparedMapPtr mirroredMap(const PreparedMap& map);

/** TsICP from `start` (other → ref cells), with the map that lies more
 * inside the other as the fixed set (TsICP trims to the share of the fixed
 * set that finds a partner: a small map inside a large one). With
 * `fixed_points` > 0, the fixed set is sampled to about that many points.
 * The result is always other → ref, in reference cells. */
TsICPResult refineFromTheInside(
	const PreparedMap& ref, const PreparedMap& other, const Similarity2D& start, const TsICPParams& ip,
	size_t fixed_points = 0);

}  // namespace multires_map_merge
