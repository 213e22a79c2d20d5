#pragma once
// Fusion (method step 4): one map on the union of both extents, in the
// reference map's world frame, each output cell filled by the paper's rule:
// occupied if either map is occupied there, else free if either is free,
// else unknown; within a class the stronger evidence is kept.

#include <multires_map_merge/GridInFrame.h>
#include <multires_map_merge/Similarity2D.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <opencv2/core.hpp>

#include <optional>
#include <stdexcept>
#include <vector>

namespace multires_map_merge
{
/** The merged map would exceed the caller's cell limit. */
struct MergedMapTooLarge : std::invalid_argument
{
	using std::invalid_argument::invalid_argument;
};

struct FusedMap
{
	/** In the reference grid's frame; `merged.origin` places it in the
	 * reference map's frame (identity for the grid overload). */
	GridInFrame merged;
	/** Each input as sampled on the merged grid (class images, row = cy):
	 * what the overlay PNG shows. */
	cv::Mat ref_classes, other_classes;
};

/** Fuses `other` into `ref`'s frame. `other_to_ref` maps other's metric
 * coordinates (its stated metadata) to ref's, as CScalingGridMapAligner's
 * TReturnInfo::metric does. Every output cell samples both maps at sub-cell
 * points (the other by the inverse transform), enough of them that no input
 * cell is skipped, so a one-cell wall survives a coarser output.
 * Throws std::invalid_argument on a non-positive or non-finite resolution or
 * an invalid transform, MergedMapTooLarge (before allocating) on an output of
 * more than `max_cells` cells. */
FusedMap fuseGridMaps(
	const mrpt::maps::COccupancyGridMap2D& ref, const mrpt::maps::COccupancyGridMap2D& other,
	const Similarity2D& other_to_ref, double output_resolution,
	size_t max_cells = size_t(1) << 28);

/** The same for maps in their frames: `other_to_ref` is between the maps'
 * frames (the GridInFrame overload of CScalingGridMapAligner::alignScaled);
 * the merged grid lies on the reference grid's cell lattice (at the
 * reference's resolution) and its origin is the reference's. */
FusedMap fuseGridMaps(
	const GridInFrame& ref, const GridInFrame& other, const Similarity2D& other_to_ref,
	double output_resolution, size_t max_cells = size_t(1) << 28);

/** Any number of maps in their frames, in one pass (the cell rule is the same
 * in any order): `to_reference[k]` places maps[k]'s frame in
 * maps[reference]'s (std::nullopt leaves map k out; the reference's own is
 * the identity). The merged grid is in the reference map's frame, as above;
 * `classes[k]` is maps[k] sampled on it (empty when left out). Throws as the
 * two-map fusion does, and std::invalid_argument when the sizes disagree. */
struct FusedMaps
{
	GridInFrame merged;
	std::vector<cv::Mat> classes;
};
FusedMaps fuseGridMaps(
	const std::vector<GridInFrame>& maps, size_t reference,
	const std::vector<std::optional<Similarity2D>>& to_reference, double output_resolution,
	size_t max_cells = size_t(1) << 28);

/** The cell rule on two occupancy probabilities (0.5 = unknown). */
float fuseCell(float p_ref, float p_other);

}  // namespace multires_map_merge
