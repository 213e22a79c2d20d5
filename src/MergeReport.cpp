#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MergeReport.h>

#include <nlohmann/json.hpp>

#include <cmath>

namespace multires_map_merge
{
namespace
{
// JSON has no NaN or infinity: null says "no value".
nlohmann::ordered_json num(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); }

nlohmann::ordered_json transformJson(const Similarity2D& t)
{
	return {{"x", num(t.t.x())}, {"y", num(t.t.y())}, {"yaw", num(t.yaw)}, {"scale", num(t.scale)}};
}
}  // namespace

std::string toJson(const CScalingGridMapAligner::TReturnInfo& r, double runtime_s)
{
	nlohmann::ordered_json stages = nlohmann::ordered_json::object();
	for (const auto& [name, secs] : r.stage_seconds) stages[name] = num(secs);
	const nlohmann::ordered_json j = {
		{"success", r.success},
		{"transform", transformJson(r.metric)},
		{"scale_cells", num(r.cells.scale)},
		{"implied_resolution_other", num(r.implied_resolution_other)},
		{"initial_transform_cells", transformJson(r.initial_cells)},
		{"overlap", num(r.overlap)},
		{"objective", num(r.objective)},
		{"inliers", r.ransac_inliers},
		{"consistency", num(r.consistency)},
		{"chance_consistency", num(r.chance_consistency)},
		{"confidence", num(r.confidence)},
		{"icp_iterations", r.icp_iterations},
		{"runtime_s", num(runtime_s)},
		{"stages", stages},
		{"error", r.success ? "" : r.message},
	};
	// Invalid UTF-8 (a file name, say) is replaced rather than thrown on.
	return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

cv::Mat overlayImage(const cv::Mat& ref, const cv::Mat& other)
{
	CV_Assert(ref.size() == other.size() && ref.type() == CV_8UC1 && other.type() == CV_8UC1);
	cv::Mat out(ref.size(), CV_8UC3, cv::Scalar(160, 160, 160));
	out.setTo(cv::Scalar(255, 255, 255), (ref == kFree) | (other == kFree));
	const cv::Mat ro = ref == kOccupied, oo = other == kOccupied;
	out.setTo(cv::Scalar(220, 90, 0), ro & ~oo);  // blue: reference only
	out.setTo(cv::Scalar(0, 40, 230), oo & ~ro);  // red: other only
	out.setTo(cv::Scalar(0, 0, 0), ro & oo);  // black: both agree
	cv::Mat flipped;
	cv::flip(out, flipped, 0);  // +y up, like forDisplay()
	return flipped;
}

}  // namespace multires_map_merge
