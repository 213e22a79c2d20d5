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
/** Every evidence field (Decision.h's one list), counts as integers. */
nlohmann::ordered_json evidenceJson(const Evidence& e)
{
	nlohmann::ordered_json j = nlohmann::ordered_json::object();
	for (const auto& f : evidenceFields())
		j[f.name] = f.count ? nlohmann::ordered_json(std::llround(e.*f.member)) : num(e.*f.member);
	return j;
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
		{"evidence", evidenceJson(r.evidence)},
		{"score", num(r.score)},
		{"runner_up_score", num(r.runner_up_score)},
		{"decision_value", num(r.decision_value)},
		{"mirror_score", num(r.mirror_score)},
		{"roles_swapped", r.roles_swapped},
		{"confidence", num(r.confidence)},
		{"icp_iterations", r.icp_iterations},
		{"runtime_s", num(runtime_s)},
		{"stages", stages},
		{"error", r.success ? "" : r.message},
	};
	// Invalid UTF-8 (a file name, say) is replaced rather than thrown on.
	return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

std::string fleetJson(
	const FleetResult& r, const std::vector<std::string>& names, size_t reference, double runtime_s,
	const std::string& error)
{
	auto name = [&](int m) { return m >= 0 && size_t(m) < names.size() ? names[m] : std::string(); };
	nlohmann::ordered_json maps = nlohmann::ordered_json::array();
	for (size_t m = 0; m < r.maps.size(); ++m)
	{
		if (m == reference) continue;
		const FleetPlacement& p = r.maps[m];
		maps.push_back({
			{"file", name(int(m))},
			{"success", p.placed},
			{"transform", p.placed ? transformJson(p.in_reference) : nlohmann::ordered_json()},
			{"confidence", num(p.confidence)},
			{"placed_through", p.parent >= 0 && size_t(p.parent) != reference ? name(p.parent) : ""},
			{"checked_by_cycle", p.checked_by_cycle},
			{"error", p.placed ? "" : p.message},
		});
	}
	nlohmann::ordered_json pairs = nlohmann::ordered_json::array();
	for (const FleetEdge& e : r.edges)
		pairs.push_back({{"ref", name(int(e.to))},
						 {"other", name(int(e.from))},
						 {"merged", e.merged && !e.dropped},
						 {"confidence", num(e.confidence)},
						 {"transform", e.merged ? transformJson(e.from_to_to) : nlohmann::ordered_json()},
						 {"message", e.describe()}});
	const nlohmann::ordered_json j = {
		{"success", error.empty() && r.allPlaced()},
		{"reference", name(int(reference))},
		{"maps", maps},
		{"pairs_aligned", r.pairs_aligned},
		{"pairs_skipped", r.pairs_skipped},
		{"pairs", pairs},
		{"runtime_s", num(runtime_s)},
		{"error", error},
	};
	return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

cv::Mat fleetOverlayImage(const std::vector<cv::Mat>& classes)
{
	// Distinct, colour-blind-friendly hues (BGR), the reference's first.
	static const cv::Scalar palette[] = {
		{178, 114, 0}, {0, 94, 213}, {115, 158, 0}, {167, 121, 204}, {0, 159, 230}, {233, 180, 86}, {66, 228, 240}, {90, 90, 90}};
	cv::Size size;
	for (const auto& c : classes)
		if (!c.empty()) size = c.size();
	CV_Assert(size.area() > 0);
	cv::Mat out(size, CV_8UC3, cv::Scalar(160, 160, 160));
	cv::Mat occupied_count = cv::Mat::zeros(size, CV_8UC1);
	for (const auto& c : classes)
		if (!c.empty())
		{
			CV_Assert(c.size() == size && c.type() == CV_8UC1);
			out.setTo(cv::Scalar(255, 255, 255), c == kFree);
			cv::add(occupied_count, (c == kOccupied) / 255, occupied_count);
		}
	for (size_t m = 0; m < classes.size(); ++m)
		if (!classes[m].empty()) out.setTo(palette[m % 8], (classes[m] == kOccupied) & (occupied_count == 1));
	out.setTo(cv::Scalar(0, 0, 0), occupied_count >= 2);  // black: walls two maps agree on
	cv::Mat flipped;
	cv::flip(out, flipped, 0);  // +y up, like forDisplay()
	return flipped;
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
