#include "plots.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace multires_bench
{
namespace
{
const cv::Scalar kBlack(0, 0, 0), kGrey(200, 200, 200), kGreen(120, 200, 120), kRed(110, 110, 230);

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale = 0.45, int thick = 1)
{
	cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, kBlack, thick, cv::LINE_AA);
}

void centred(cv::Mat& img, const std::string& s, cv::Point centre, double scale = 0.4)
{
	int base = 0;
	const cv::Size sz = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base);
	text(img, s, {centre.x - sz.width / 2, centre.y + sz.height / 2}, scale);
}
}  // namespace

cv::Mat successMatrix(
	const std::string& title, const std::vector<std::string>& row_labels, const std::string& row_axis,
	const std::vector<std::string>& col_labels, const std::string& col_axis,
	const std::vector<std::vector<MatrixCell>>& cells)
{
	const int cw = 64, ch = 40, left = 110, top = 70;
	int base = 0;
	const int title_w = cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, 0.55, 1, &base).width;
	const int w = std::max(left + cw * int(col_labels.size()) + 20, title_w + 20);
	const int h = top + ch * int(row_labels.size()) + 20;
	cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
	text(img, title, {10, 22}, 0.55, 1);
	text(img, col_axis, {left, 44});
	text(img, row_axis, {6, top - 8});
	for (size_t c = 0; c < col_labels.size(); ++c) centred(img, col_labels[c], {left + int(c) * cw + cw / 2, top - 10});
	for (size_t r = 0; r < row_labels.size(); ++r)
	{
		centred(img, row_labels[r], {left - 30, top + int(r) * ch + ch / 2});
		for (size_t c = 0; c < col_labels.size(); ++c)
		{
			const MatrixCell& m = cells[r][c];
			const cv::Rect box(left + int(c) * cw, top + int(r) * ch, cw, ch);
			cv::rectangle(img, box, !m.ran ? kGrey : (m.ok ? kGreen : kRed), cv::FILLED);
			cv::rectangle(img, box, cv::Scalar(255, 255, 255), 1);
			centred(img, m.text, {box.x + cw / 2, box.y + ch / 2}, 0.38);
		}
	}
	return img;
}

cv::Mat logLogPlot(
	const std::string& title, const std::string& x_axis, const std::string& y_axis,
	const std::vector<Series>& series)
{
	const int w = 640, h = 440, left = 80, right = 170, top = 40, bottom = 60;
	cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
	double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
	for (const auto& s : series)
		for (size_t i = 0; i < s.x.size(); ++i)
			if (s.x[i] > 0 && s.y[i] > 0)
			{
				x0 = std::min(x0, std::log10(s.x[i])), x1 = std::max(x1, std::log10(s.x[i]));
				y0 = std::min(y0, std::log10(s.y[i])), y1 = std::max(y1, std::log10(s.y[i]));
			}
	if (x0 > x1) return img;
	x0 = std::floor(x0), x1 = std::ceil(x1 + 1e-9), y0 = std::floor(y0), y1 = std::ceil(y1 + 1e-9);
	if (x1 == x0) x1 += 1;
	if (y1 == y0) y1 += 1;
	const int pw = w - left - right, ph = h - top - bottom;
	auto px = [&](double x, double y) {
		return cv::Point(
			left + int((std::log10(x) - x0) / (x1 - x0) * pw), top + ph - int((std::log10(y) - y0) / (y1 - y0) * ph));
	};
	cv::rectangle(img, {left, top, pw, ph}, kBlack, 1);
	for (double d = x0; d <= x1; d += 1)
	{
		const int x = left + int((d - x0) / (x1 - x0) * pw);
		cv::line(img, {x, top}, {x, top + ph}, kGrey, 1);
		std::ostringstream s;
		s << std::pow(10.0, d);
		centred(img, s.str(), {x, top + ph + 14});
	}
	for (double d = y0; d <= y1; d += 1)
	{
		const int y = top + ph - int((d - y0) / (y1 - y0) * ph);
		cv::line(img, {left, y}, {left + pw, y}, kGrey, 1);
		std::ostringstream s;
		s << std::pow(10.0, d);
		text(img, s.str(), {6, y + 4}, 0.38);
	}
	text(img, title, {10, 22}, 0.55);
	centred(img, x_axis, {left + pw / 2, h - 20}, 0.45);
	text(img, y_axis, {left, top - 6}, 0.4);
	int legend_y = top + 10;
	for (const auto& s : series)
	{
		cv::Point prev(-1, -1);
		for (size_t i = 0; i < s.x.size(); ++i)
		{
			if (!(s.x[i] > 0 && s.y[i] > 0)) continue;
			const cv::Point p = px(s.x[i], s.y[i]);
			cv::circle(img, p, 4, s.colour, cv::FILLED, cv::LINE_AA);
			if (prev.x >= 0) cv::line(img, prev, p, s.colour, 2, cv::LINE_AA);
			prev = p;
		}
		cv::line(img, {w - right + 10, legend_y}, {w - right + 30, legend_y}, s.colour, 3);
		text(img, s.name, {w - right + 36, legend_y + 4}, 0.4);
		legend_y += 20;
	}
	return img;
}

}  // namespace multires_bench
