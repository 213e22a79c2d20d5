#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/StructureHypotheses.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>
#include <opencv2/core/utility.hpp>

namespace multires_map_merge
{
namespace
{
/** Cell coordinates of a map resampled by `f` (cell centres at integers). */
Similarity2D resampling(double f) { return Similarity2D(f, 0, {0.5 * (f - 1), 0.5 * (f - 1)}); }

/** The walls (`occupied`: 255 on wall cells) at `f` times the map's size as
 * 0/1 floats, a cell a wall where any wall cell lies under it (as
 * resampleClasses keeps walls), blurred by `blur` cells. */
cv::Mat wallImage(const cv::Mat& occupied, double f, double blur = 1.0)
{
	cv::Mat walls;
	(f < 1 ? resampleMask(occupied, f) : occupied).convertTo(walls, CV_32F, 1.0 / 255);
	cv::GaussianBlur(walls, walls, cv::Size(0, 0), blur);
	return walls;
}

double fitFactor(const cv::Mat& img, int size)
{
	return std::min(1.0, double(size) / std::max(img.cols, img.rows));
}

struct Scored
{
	Similarity2D other_to_ref;
	double score;
};
}  // namespace

double dominantWallDirection(const cv::Mat& classes)
{
	// Walls at an angle are staircases of cells, whose gradients lean to the
	// axes: blur well past a cell before taking directions.
	const cv::Mat walls = wallImage(classes == kOccupied, fitFactor(classes, 768), 3.0);
	cv::Mat gx, gy;
	cv::Sobel(walls, gx, CV_32F, 1, 0);
	cv::Sobel(walls, gy, CV_32F, 0, 1);
	// Directions modulo 90° as angles 4θ on a circle: the weighted circular
	// mean is the dominant direction of walls at right angles. With the
	// gradient as z = a + ib, m²·e^{i4θ} = z⁴ / |z|²: no trigonometry per cell.
	double c = 0, s = 0;
	for (int y = 0; y < walls.rows; ++y)
		for (int x = 0; x < walls.cols; ++x)
		{
			const double a = gx.at<float>(y, x), b = gy.at<float>(y, x);
			const double m2 = a * a + b * b;
			if (m2 < 1e-8) continue;
			const double a2 = a * a, b2 = b * b;
			c += (a2 * a2 - 6 * a2 * b2 + b2 * b2) / m2, s += 4 * a * b * (a2 - b2) / m2;
		}
	double d = std::atan2(s, c) / 4;
	if (d < 0) d += M_PI / 2;
	return d;
}

double MapWalls::dominantDirection() const
{
	std::call_once(direction_once_, [this] { direction_ = dominantWallDirection(classes_); });
	return direction_;
}

cv::Mat MapWalls::at(double f) const
{
	{
		std::lock_guard<std::mutex> lock(mutex_);
		if (auto it = walls_.find(f); it != walls_.end()) return it->second;
	}
	// Made outside the lock (the threads would wait on each other); the first one made kept.
	cv::Mat made = wallImage(occupied_, f);
	std::lock_guard<std::mutex> lock(mutex_);
	return walls_.emplace(f, std::move(made)).first->second;
}

namespace
{
/** The reference's walls at the sizes the poses need (the other map is
 * never enlarged: the reference shrinks instead; MapWalls keeps the images
 * for the reference's next pair), each within its bounding
 * box (the rest of a map is often unexplored margin: the correlation is the
 * same, its DFTs smaller), with their spectra per canvas. Shared by the
 * pose threads: made outside the lock (the threads would wait on each
 * other), the first one made kept. */
class RefViews
{
   public:
	struct View
	{
		double f = 0;  //!< ref full cells → this image
		cv::Mat walls;  //!< within their bounding box ...
		cv::Point corner;  //!< ... whose corner this is in the whole image
		bool has_walls = false;  //!< any wall left at this size
	};

	RefViews(const MapWalls& ref, double f_ref) : ref_(ref)
	{
		views_.emplace(f_ref, Entry{makeView(f_ref, ref.at(f_ref)), {}});
	}

	const View& at(double f)
	{
		{
			std::lock_guard<std::mutex> lock(mutex_);
			if (auto it = views_.find(f); it != views_.end()) return it->second.view;
		}
		View made = makeView(f, ref_.at(f));
		std::lock_guard<std::mutex> lock(mutex_);
		return views_.emplace(f, Entry{std::move(made), {}}).first->second.view;
	}

	/** The view's walls (squared 0) or walls² (1) on `canvas`, packed (CCS). */
	cv::Mat spectrum(const View& v, int squared, cv::Size canvas)
	{
		const std::tuple key{squared, canvas.width, canvas.height};
		{
			std::lock_guard<std::mutex> lock(mutex_);
			const auto& spectra = views_.at(v.f).spectra;
			if (auto it = spectra.find(key); it != spectra.end()) return it->second;
		}
		cv::Mat made = packedSpectrum(squared ? v.walls.mul(v.walls) : v.walls, canvas);
		std::lock_guard<std::mutex> lock(mutex_);
		return views_.at(v.f).spectra.emplace(key, std::move(made)).first->second;
	}

	/** A real image's spectrum on `canvas`, packed (CCS): half the work of a complex one. */
	static cv::Mat packedSpectrum(const cv::Mat& img, cv::Size canvas)
	{
		cv::Mat pad = cv::Mat::zeros(canvas, CV_32F), f;
		img.copyTo(pad(cv::Rect(0, 0, img.cols, img.rows)));
		cv::dft(pad, f, 0, img.rows);
		return f;
	}

   private:
	struct Entry
	{
		View view;
		std::map<std::tuple<int, int, int>, cv::Mat> spectra;
	};
	static View makeView(double f, const cv::Mat& whole)
	{
		View v;
		v.f = f;
		const cv::Rect box = cv::boundingRect(whole > 0);
		v.has_walls = !box.empty();
		v.walls = v.has_walls ? whole(box) : whole;
		v.corner = box.tl();
		return v;
	}

	const MapWalls& ref_;
	std::map<double, Entry> views_;  // by factor
	std::mutex mutex_;
};

/** The box `lin` maps an image of `size` onto. */
std::pair<Eigen::Vector2d, Eigen::Vector2d> placedBox(const Similarity2D& lin, cv::Size size)
{
	Eigen::Vector2d lo(1e18, 1e18), hi(-1e18, -1e18);
	for (const Eigen::Vector2d& c : {Eigen::Vector2d(0, 0), Eigen::Vector2d(size.width, 0),
									 Eigen::Vector2d(0, size.height), Eigen::Vector2d(size.width, size.height)})
		lo = lo.cwiseMin(lin(c)), hi = hi.cwiseMax(lin(c));
	return {lo, hi};
}

/** Shifts past the middle of the canvas are negative: the FFT wraps. */
int signedShift(int i, int canvas, int img) { return i > canvas - img ? i - canvas : i; }

/** C(i) = Σ walls(x)·img(x − i) (walls² with `squared`) for every shift i
 * on a canvas that holds both. */
cv::Mat correlate(RefViews& views, const RefViews::View& view, int squared, const cv::Mat& img)
{
	const cv::Size canvas(
		cv::getOptimalDFTSize(view.walls.cols + img.cols), cv::getOptimalDFTSize(view.walls.rows + img.rows));
	cv::Mat prod, c;
	cv::mulSpectrums(views.spectrum(view, squared, canvas), RefViews::packedSpectrum(img, canvas), prod, 0, true);
	cv::dft(prod, c, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
	return c;
}

/** The other map's walls placed by one pose (scale × right-angle turn), up to a translation. */
struct PlacedOther
{
	Similarity2D place;  //!< other's working image → this image
	cv::Mat walls, footprint;  //!< the warped walls, and where the other map lies at all
	double energy = 0;  //!< Σ walls²
};

/** The masked normalised cross-correlation of the placed other map with the
 * reference's walls: Σ a·b over the energy of both where they overlap, so a
 * shrunken, dense copy of the other map cannot win by touching many walls.
 * Two correlations on two canvases: the walls' needs only the other map's
 * walls (their bounding box, `walls_box`), the energy's the whole footprint.
 * Index i of the result is the other map placed at i − the walls' corner. */
cv::Mat normalisedCorrelation(
	RefViews& views, const RefViews::View& view, const PlacedOther& other, const cv::Rect& walls_box)
{
	const cv::Mat other_walls = other.walls(walls_box);
	cv::Mat corr = correlate(views, view, 0, other_walls);
	const cv::Mat a_energy = correlate(views, view, 1, other.footprint);
	std::vector<int> energy_col(corr.cols);
	for (int i = 0; i < corr.cols; ++i)
		energy_col[i] = (signedShift(i, corr.cols, other_walls.cols) - walls_box.x + a_energy.cols) % a_energy.cols;
	for (int r = 0; r < corr.rows; ++r)
	{
		const int er = (signedShift(r, corr.rows, other_walls.rows) - walls_box.y + a_energy.rows) % a_energy.rows;
		const float* e = a_energy.ptr<float>(er);
		float* c = corr.ptr<float>(r);
		for (int i = 0; i < corr.cols; ++i)
			c[i] /= float(std::sqrt(std::max(double(e[energy_col[i]]), 1e-3 * other.energy) * other.energy));
	}
	return corr;
}

/** The `peaks` highest correlations, each as the other map's working image
 * placed in the view's (a peak's neighbours, on the wrapped shifts too,
 * cleared before the next: the canvas's seam runs between shifts 0 and -1). */
std::vector<std::pair<Similarity2D, double>> takePeaks(
	cv::Mat corr, const RefViews::View& view, const PlacedOther& other, const cv::Rect& walls_box, int peaks)
{
	std::vector<std::pair<Similarity2D, double>> out;
	for (int peak = 0; peak < peaks; ++peak)
	{
		double best;
		cv::Point at;
		cv::minMaxLoc(corr, nullptr, &best, nullptr, &at);
		if (!(best > 0)) break;
		const double dx = signedShift(at.x, corr.cols, walls_box.width) - walls_box.x,
					 dy = signedShift(at.y, corr.rows, walls_box.height) - walls_box.y;
		out.emplace_back(
			Similarity2D(other.place.scale, other.place.yaw,
						 other.place.t + Eigen::Vector2d(dx + view.corner.x, dy + view.corner.y)),
			best);
		for (int ox : {-corr.cols, 0, corr.cols})
			for (int oy : {-corr.rows, 0, corr.rows})
				cv::circle(corr, at + cv::Point(ox, oy), 6, cv::Scalar(0), cv::FILLED);
	}
	return out;
}

/** What every pose of one search shares. */
struct PoseSearch
{
	const cv::Mat& other_walls;  //!< the other map's walls at its working size
	double f_ref, f_other;
	int working_size, peaks;
	RefViews& views;
};

/** One pose (scale `s`, turn `yaw`): the other map placed, correlated with
 * the reference's walls at the size that keeps it unenlarged, its peaks as
 * other's full cells → ref's full cells. Nothing if the pose does not fit. */
std::vector<Scored> searchPose(const PoseSearch& ps, double s, double yaw)
{
	const cv::Mat& b0 = ps.other_walls;
	{
		// The poses searched: those whose other map fits three working sizes
		// at the reference's working size (as before the shrink).
		const auto [lo, hi] = placedBox(Similarity2D(s * ps.f_ref / ps.f_other, yaw, {0, 0}), b0.size());
		if (hi.x() - lo.x() + 1 > 3 * ps.working_size || hi.y() - lo.y() + 1 > 3 * ps.working_size) return {};
	}
	// Where the other map would be enlarged (scale above one), the reference
	// is shrunk instead: the canvas, and with it the DFTs, stay about twice
	// the working size instead of growing with the scale, at the same
	// resolution of the other map's cells.
	const double f_view = ps.f_ref * std::min(1.0, ps.f_other / (s * ps.f_ref));
	const Similarity2D lin(s * f_view / ps.f_other, yaw, {0, 0});
	const auto [lo, hi] = placedBox(lin, b0.size());
	const int bw = static_cast<int>(std::ceil(hi.x() - lo.x())) + 1, bh = static_cast<int>(std::ceil(hi.y() - lo.y())) + 1;
	if (bw < 8 || bh < 8) return {};
	PlacedOther other;
	other.place = Similarity2D(lin.scale, lin.yaw, -lo);  // into a bw × bh image
	const Eigen::Matrix2d l = other.place.linear();
	const cv::Mat m = (cv::Mat_<double>(2, 3) << l(0, 0), l(0, 1), other.place.t.x(), l(1, 0), l(1, 1), other.place.t.y());
	cv::warpAffine(b0, other.walls, m, cv::Size(bw, bh), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
	other.energy = cv::sum(other.walls.mul(other.walls))[0];
	if (other.energy <= 0) return {};
	const RefViews::View& view = ps.views.at(f_view);
	if (!view.has_walls) return {};
	cv::warpAffine(cv::Mat::ones(b0.size(), CV_32F), other.footprint, m, cv::Size(bw, bh), cv::INTER_NEAREST);
	const cv::Rect walls_box = cv::boundingRect(other.walls > 0);
	std::vector<Scored> found;
	const Similarity2D other_down = resampling(ps.f_other);
	for (const auto& [working, score] :
		 takePeaks(normalisedCorrelation(ps.views, view, other, walls_box), view, other, walls_box, ps.peaks))
		found.push_back({resampling(view.f).inverse().compose(working).compose(other_down), score});
	return found;
}

/** The correlation peaks (`peaks` per pose; pose = scale index × 4 +
 * right-angle turn), with both maps at most `working_size` across; empty
 * where a pose was skipped. */
std::vector<std::vector<Scored>> searchPoses(
	const MapWalls& ref, const MapWalls& other, int working_size, const std::vector<double>& scales, double turn,
	int peaks)
{
	std::vector<std::vector<Scored>> found_per_pose(scales.size() * 4);
	const double f_ref = fitFactor(ref.classes(), working_size);
	const double f_other = fitFactor(other.classes(), working_size);
	const cv::Mat a = ref.at(f_ref), b0 = other.at(f_other);
	if (cv::sum(a)[0] <= 0 || cv::sum(b0.mul(b0))[0] <= 0) return found_per_pose;
	RefViews views(ref, f_ref);
	const PoseSearch ps{b0, f_ref, f_other, working_size, peaks, views};
	// The poses are independent: searched in parallel, each keeping its own
	// peaks, gathered in pose order so the result does not depend on the threads.
	cv::parallel_for_(cv::Range(0, int(scales.size() * 4)), [&](const cv::Range& range) {
		for (int pose = range.start; pose < range.end; ++pose)
			found_per_pose[pose] = searchPose(ps, scales[pose / 4], turn + (pose % 4) * M_PI / 2);
	});
	return found_per_pose;
}
}  // namespace

std::vector<Hypothesis> structureHypotheses(
	const cv::Mat& ref_classes, const cv::Mat& other_classes, const StructureParams& p,
	std::optional<double> expected_scale)
{
	return structureHypotheses(MapWalls(ref_classes), MapWalls(other_classes), p, expected_scale);
}

std::vector<Hypothesis> structureHypotheses(
	const MapWalls& ref, const MapWalls& other, const StructureParams& p, std::optional<double> expected_scale)
{
	std::vector<Hypothesis> out;
	if (ref.classes().empty() || other.classes().empty()) return out;
	std::vector<double> scales;  // other full cells → ref full cells
	if (expected_scale)
		scales = {*expected_scale};
	else
		for (int k = static_cast<int>(std::floor(std::log2(p.min_scale) * p.steps_per_octave));
			 std::pow(2.0, double(k) / p.steps_per_octave) <= p.max_scale * 1.0001; ++k)
			if (std::pow(2.0, double(k) / p.steps_per_octave) >= p.min_scale * 0.9999)
				scales.push_back(std::pow(2.0, double(k) / p.steps_per_octave));
	const double turn = ref.dominantDirection() - other.dominantDirection();
	const auto found_per_pose = searchPoses(ref, other, p.working_size, scales, turn, p.peaks_per_pose);
	const double f_ref = fitFactor(ref.classes(), p.working_size);
	std::vector<Scored> found;
	for (const auto& f : found_per_pose) found.insert(found.end(), f.begin(), f.end());
	std::sort(found.begin(), found.end(), [](const Scored& x, const Scored& y) { return x.score > y.score; });
	for (const auto& f : found)
	{
		if (static_cast<int>(out.size()) >= p.max_hypotheses) break;
		const bool seen = std::any_of(out.begin(), out.end(), [&](const Hypothesis& h) {
			return std::abs(std::log(h.other_to_ref.scale / f.other_to_ref.scale)) < 0.05 &&
				std::abs(wrapToPi(h.other_to_ref.yaw - f.other_to_ref.yaw)) < 0.1 &&
				(h.other_to_ref.t - f.other_to_ref.t).norm() < 10 / f_ref;
		});
		if (seen) continue;
		Hypothesis h;
		h.other_to_ref = f.other_to_ref;
		h.inliers = static_cast<int>(std::lround(1000 * f.score));
		h.ref_level = h.other_level = -1;  // not from a pyramid level pair
		out.push_back(h);
	}
	return out;
}

}  // namespace multires_map_merge
