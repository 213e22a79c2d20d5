#pragma once
// The benchmark's pictures, drawn with OpenCV (no plotting stack needed):
// success matrices like the paper's Fig. 8/9 and log-log cost curves.

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace multires_bench
{
/** One matrix cell: did the pair merge, and the number printed in it. */
struct MatrixCell
{
	bool ok = false;
	bool ran = false;  //!< false: not run (drawn grey)
	std::string text;
};

/** A rows × cols success matrix: green merged, red not, grey not run; each
 * cell labelled with its text, rows and columns with theirs. */
cv::Mat successMatrix(
	const std::string& title, const std::vector<std::string>& row_labels, const std::string& row_axis,
	const std::vector<std::string>& col_labels, const std::string& col_axis,
	const std::vector<std::vector<MatrixCell>>& cells);

struct Series
{
	std::string name;
	std::vector<double> x, y;
	cv::Scalar colour;
};

/** Log-log plot of one or more series on shared axes. */
cv::Mat logLogPlot(
	const std::string& title, const std::string& x_axis, const std::string& y_axis,
	const std::vector<Series>& series);

}  // namespace multires_bench
