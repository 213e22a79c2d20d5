#pragma once
// How well two maps agree under a transform, judged on their cells rather
// than on the edge points TsICP fitted: a wrong alignment puts walls of one
// map across free space of the other, which point distances alone can hide
// when both maps have many similar walls.

#include <multires_map_merge/Similarity2D.h>

#include <opencv2/core.hpp>

namespace multires_map_merge
{
struct Agreement
{
	/** Occupied cells (of either map, in reference cells) that fall where the
	 * other map knows the space. */
	size_t occupied_overlap = 0;
	/** Of those, the ones the other map sees as clearly free (not within one
	 * coarse cell of an obstacle or the unknown). */
	size_t conflicts = 0;
	/** 1 − conflicts / occupied_overlap; 0 when nothing overlaps. */
	double consistency = 0;
};

Agreement mapAgreement(
	const cv::Mat& ref_classes, const cv::Mat& other_classes, const Similarity2D& other_to_ref_cells);

}  // namespace multires_map_merge
