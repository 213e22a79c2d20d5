#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/MergeReport.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace multires_map_merge
{
namespace
{
std::string quoted(const std::string& s)
{
	std::ostringstream o;
	o << '"';
	for (const unsigned char c : s)
	{
		if (c == '"' || c == '\\') o << '\\' << c;
		else if (c < 0x20) o << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
		else o << c;
	}
	o << '"';
	return o.str();
}
// JSON has no NaN or infinity.
std::string num(double v)
{
	if (!std::isfinite(v)) return "null";
	std::ostringstream o;
	o << std::setprecision(10) << v;
	return o.str();
}
}  // namespace

std::string toJson(const CScalingGridMapAligner::TReturnInfo& r, double runtime_s)
{
	std::ostringstream j;
	j << "{\n  \"success\": " << (r.success ? "true" : "false") << ",\n";
	j << "  \"transform\": {\"x\": " << num(r.metric.t.x()) << ", \"y\": " << num(r.metric.t.y())
	  << ", \"yaw\": " << num(r.metric.yaw) << ", \"scale\": " << num(r.metric.scale) << "},\n";
	j << "  \"scale_cells\": " << num(r.cells.scale) << ",\n";
	j << "  \"implied_resolution_other\": " << num(r.implied_resolution_other) << ",\n";
	j << "  \"initial_transform_cells\": {\"x\": " << num(r.initial_cells.t.x()) << ", \"y\": "
	  << num(r.initial_cells.t.y()) << ", \"yaw\": " << num(r.initial_cells.yaw)
	  << ", \"scale\": " << num(r.initial_cells.scale) << "},\n";
	j << "  \"overlap\": " << num(r.overlap) << ",\n";
	j << "  \"objective\": " << num(r.objective) << ",\n";
	j << "  \"inliers\": " << r.ransac_inliers << ",\n";
	j << "  \"consistency\": " << num(r.consistency) << ",\n";
	j << "  \"confidence\": " << num(r.confidence) << ",\n";
	j << "  \"icp_iterations\": " << r.icp_iterations << ",\n";
	j << "  \"runtime_s\": " << num(runtime_s) << ",\n";
	j << "  \"stages\": {";
	bool first = true;
	for (const auto& [name, secs] : r.stage_seconds)
		j << (first ? "" : ", ") << quoted(name) << ": " << num(secs), first = false;
	j << "},\n";
	j << "  \"error\": " << quoted(r.success ? "" : r.message) << "\n}\n";
	return j.str();
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
