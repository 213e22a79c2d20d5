#include "report.h"

#include "plots.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>

namespace multires_bench
{
using namespace multires_map_merge;

namespace
{
/** The q-quantile of the finite values (NaN if none). */
double quantile(std::vector<double> v, double q)
{
	v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
	if (v.empty()) return NAN;
	std::sort(v.begin(), v.end());
	return v[std::min(v.size() - 1, size_t(std::ceil(q * v.size())) - (q > 0 ? 1 : 0))];
}

bool isSameResolutionWithMrpt(const PairResult& r)
{
	return r.set == "resolution" && r.ref_res == r.other_res && r.mrpt_ran;
}
double oursOverMrpt(const PairResult& r) { return r.seconds / std::max(1e-9, r.mrpt_seconds); }

/** One Halmstad site's sensor pairs. */
/** What more than one section reads (a section's text, a target): computed once. */
struct Facts
{
	std::vector<double> same_resolution_ratios;  //!< ours / MRPT, fr079 same-resolution pairs
	double worst_process_ratio = 0;  //!< whole processes, ours / MRPT
	std::vector<double> fig8_secs, fig9_secs, mrpt_fig8_secs;  //!< alignment times (NaN: not of the set)
	size_t false_merges = 0;  //!< CARMEN negatives merged
	std::map<std::string, HalmstadTally> sites;  //!< Halmstad sensor pairs per site
	std::vector<double> halmstad_secs;  //!< every same-site sensor pair
	size_t acceptance_pairs = 0, acceptance_right = 0, calibration_pairs = 0, calibration_right = 0;
	size_t halmstad_wrong = 0, cross = 0, cross_merged = 0;
};

Facts factsOf(const FullRun& run)
{
	Facts f;
	for (const auto& r : run.pairs)
		if (isSameResolutionWithMrpt(r)) f.same_resolution_ratios.push_back(oursOverMrpt(r));
	for (const auto& p : run.processes) f.worst_process_ratio = std::max(f.worst_process_ratio, p.ours_s / std::max(1e-9, p.mrpt_s));
	f.fig8_secs = column(run.pairs, [](auto& r) { return r.set == "resolution" ? r.seconds : NAN; });
	f.fig9_secs = column(run.pairs, [](auto& r) { return r.set == "rotation" ? r.seconds : NAN; });
	// MRPT "runs" every pair but refuses different resolutions at once: only the pairs it aligns count.
	f.mrpt_fig8_secs = column(run.pairs, [](auto& r) {
		return r.set == "resolution" && r.mrpt_ran && r.ref_res == r.other_res ? r.mrpt_seconds : NAN;
	});
	for (const auto& n : run.negatives) f.false_merges += n.merged;
	for (const auto& h : run.halmstad)
	{
		if (!h.positive)
		{
			++f.cross, f.cross_merged += h.merged;
			continue;
		}
		f.halmstad_secs.push_back(h.seconds);
		f.sites[h.site].add(h);
	}
	for (const auto& [site, row] : f.sites)
	{
		const bool cal = isCalibrationSite(site);
		(cal ? f.calibration_pairs : f.acceptance_pairs) += row.pairs;
		(cal ? f.calibration_right : f.acceptance_right) += row.right;
		f.halmstad_wrong += row.wrong;
	}
	return f;
}

void writeCsv(const std::string& path, const std::vector<PairResult>& rs)
{
	std::ofstream f(path);
	f << "set,log,ref_res,other_res,yaw_deg,ref_w,ref_h,other_w,other_h,merged,correct,rmse_coarse_cells,yaw_err_deg,"
		 "scale_err_pct,implied_res_err_pct,overlap,true_overlap,confidence,seconds,features_s,ransac_s,edges_s,icp_s,"
		 "verify_s,mrpt_ran,mrpt_correct,mrpt_rmse_coarse_cells,mrpt_yaw_err_deg,mrpt_seconds,message,mrpt_why\n";
	auto q = [](std::string s) {
		std::replace(s.begin(), s.end(), '"', '\'');
		return "\"" + s + "\"";
	};
	for (const auto& r : rs)
	{
		auto st = [&](const char* k) { return r.stages.count(k) ? r.stages.at(k) : NAN; };
		f << r.set << "," << r.log << "," << r.ref_res << "," << r.other_res << "," << r.yaw_deg << "," << r.ref_w
		  << "," << r.ref_h << "," << r.other_w << "," << r.other_h << "," << r.merged << "," << r.correct << ","
		  << r.rmse << "," << r.yaw_err << "," << r.scale_err_pct << "," << r.implied_err_pct << "," << r.overlap
		  << "," << r.true_overlap << "," << r.confidence << "," << r.seconds << "," << st("features") << ","
		  << st("ransac") << "," << st("edges") << "," << st("icp") << "," << st("verify") << "," << r.mrpt_ran
		  << "," << r.mrpt_correct << "," << r.mrpt_rmse << "," << r.mrpt_yaw_err << "," << r.mrpt_seconds << ","
		  << q(r.message) << "," << q(r.mrpt_why) << "\n";
	}
}

/** A success matrix of the fr079 pairs of `set`: rows by reference
 * resolution (or yaw), columns by the other's resolution; ours or MRPT's. */
std::vector<std::vector<MatrixCell>> matrixOf(
	const std::vector<PairResult>& all, const std::string& set, const std::vector<double>& rows,
	const std::vector<double>& cols, bool rows_are_yaw, bool mrpt)
{
	std::vector<std::vector<MatrixCell>> m(rows.size(), std::vector<MatrixCell>(cols.size()));
	for (const auto& r : all)
	{
		if (r.set != set || r.log != "fr079") continue;
		const double rv = rows_are_yaw ? r.yaw_deg : r.ref_res;
		const auto ri = std::find_if(rows.begin(), rows.end(), [&](double v) { return std::abs(v - rv) < 1e-9; });
		const auto ci = std::find_if(cols.begin(), cols.end(), [&](double v) { return std::abs(v - r.other_res) < 1e-9; });
		if (ri == rows.end() || ci == cols.end()) continue;
		MatrixCell& c = m[ri - rows.begin()][ci - cols.begin()];
		c.ran = !mrpt || r.mrpt_ran;
		c.ok = mrpt ? r.mrpt_correct : r.correct;
		c.text = mrpt ? (r.mrpt_correct ? num(r.mrpt_rmse, 2) : (r.mrpt_ran ? "fail" : ""))
					  : (r.correct ? num(r.rmse, 2) : (r.merged ? "wrong" : "no"));
	}
	return m;
}

/** The paper's Fig. 8 and 9 matrices, ours and MRPT's. */
void writeMatrixFigures(const std::string& out, const FullRun& run)
{
	const auto& all = run.pairs;
	const auto &res = run.res, &rot_res = run.rot_res, &yaws = run.yaws;
	std::vector<std::string> res_labels, yaw_labels;
	for (double r : res) res_labels.push_back(cm(r) + " cm");
	for (double y : yaws) yaw_labels.push_back(num(y, 0) + " deg");
	std::vector<std::string> rot_labels;
	for (double r : rot_res) rot_labels.push_back(cm(r) + " cm");
	cv::imwrite(out + "/fig8_resolution_matrix_ours.png",
				successMatrix("fr079: ours (RMSE in coarse cells; green = merged within 2 cells)", res_labels,
							  "reference", res_labels, "other map's resolution",
							  matrixOf(all, "resolution", res, res, false, false)));
	cv::imwrite(out + "/fig8_resolution_matrix_mrpt.png",
				successMatrix("fr079: MRPT CGridMapAligner (featsPerSquareMeter 0.1)", res_labels, "reference",
							  res_labels, "other map's resolution", matrixOf(all, "resolution", res, res, false, true)));
	cv::imwrite(out + "/fig9_rotation_matrix_ours.png",
				successMatrix("fr079, reference 2 cm: ours by rotation and other's resolution", yaw_labels,
							  "rotation", rot_labels, "other map's resolution",
							  matrixOf(all, "rotation", yaws, rot_res, true, false)));
}

/** TsICP's basins of convergence (Fig. 7). */
void writeBasinFigures(const std::string& out, const FullRun& run)
{
	const auto &dyaws = run.basin_dyaws, &dscales = run.basin_dscales;
	const auto &basin_same = run.basin_same, &basin_ratio = run.basin_ratio;
	std::vector<std::vector<MatrixCell>> m1(dyaws.size(), std::vector<MatrixCell>(dscales.size())), m2 = m1;
	for (size_t i = 0; i < basin_same.size(); ++i)
	{
		auto& c1 = m1[i / dscales.size()][i % dscales.size()];
		c1 = {basin_same[i].converged, true, num(basin_same[i].rmse, 2)};
		auto& c2 = m2[i / dscales.size()][i % dscales.size()];
		c2 = {basin_ratio[i].converged, true, num(basin_ratio[i].rmse, 2)};
	}
	std::vector<std::string> yl, sl;
	for (double d : dyaws) yl.push_back(num(d, 0) + " deg");
	for (double d : dscales) sl.push_back(num(d, 0) + " %");
	cv::imwrite(out + "/fig7_basin_5cm_5cm.png",
				successMatrix("TsICP from perturbed truth, fr079 5 vs 5 cm (RMSE, coarse cells)", yl,
							  "rotation error", sl, "scale error", m1));
	cv::imwrite(out + "/fig7_basin_2cm_10cm.png",
				successMatrix("TsICP from perturbed truth, fr079 2 vs 10 cm (RMSE, coarse cells)", yl,
							  "rotation error", sl, "scale error", m2));
}

/** Runtime and memory against map size, runtime against the resolution ratio. */
void writeScalingFigures(const std::string& out, const FullRun& run)
{
	const auto& all = run.pairs;
	const auto& res = run.res;
	const auto& scaling = run.scaling;
	Series t{"runtime [s]", {}, {}, cv::Scalar(200, 80, 40)}, mem{"peak RSS [100 MB]", {}, {}, cv::Scalar(40, 140, 40)};
	for (const auto& c : scaling)
	{
		const double cells = double(c.ref_w) * c.ref_h;
		t.x.push_back(cells), t.y.push_back(c.seconds);
		mem.x.push_back(cells), mem.y.push_back(c.peak_mb / 100);
	}
	cv::imwrite(out + "/scaling_size.png",
				logLogPlot("fr079 pair, other at half the resolution", "reference cells", "", {t, mem}));
	Series byratio{"runtime [s]", {}, {}, cv::Scalar(200, 80, 40)};
	for (const double ro : res)
		for (const auto& r : all)
			if (r.set == "resolution" && r.log == "fr079" && std::abs(r.ref_res - 0.02) < 1e-9 &&
				std::abs(r.other_res - ro) < 1e-9)
				byratio.x.push_back(ro / 0.02), byratio.y.push_back(r.seconds);
	cv::imwrite(out + "/scaling_ratio.png",
				logLogPlot("fr079, reference 2 cm", "resolution ratio (other / reference)", "", {byratio}));
}

void writeProtocol(std::ostream& md, const BenchContext& ctx, const std::string& out, const FullRun& run)
{
	md << "# multires_map_merge benchmark report\n\n"
	   << "Generated by `multires_bench" << (ctx.quick ? " --quick" : "") << " --out " << out << "` ("
	   << (ctx.quick ? "quick mode: a few pairs" : "full run") << ") on " << machine() << ", in "
	   << num(run.seconds / 60, 1) << " min. Every number below comes from that run; per-pair rows are in "
	   << "`pairs.csv`.\n\n"
	   << "Protocol (the paper's): a SLAM-corrected CARMEN log from `../shared/data/carmen_corrected` is split; "
	   << "the reference renders the first 60 % of the scans, the other the last 60 % in a frame rotated by "
	   << "the given angle and shifted by (1.5, -2.5) m; ground truth is exact. Each map is fed as users feed it: "
	   << "written as a map_server `.yaml` + `.pgm` whose origin lies off the cell lattice (a sub-cell offset "
	   << "drawn per map, as every `map_saver` output has) and read back by the loader. A pair **succeeds** when it is "
	   << "reported merged *and* the point RMSE of the other map's edge points is ≤ 2 cells of the coarser map. "
	   << "MRPT's `CGridMapAligner` gets the same pairs as a `CMultiMetricMap` (grid + points map of occupied "
	   << "cells), `featsPerSquareMeter = 0.1`, all else default; it refuses different resolutions, which count "
	   << "as failures (Table III of the paper). MRPT is judged on accuracy alone (it has no refusal).\n\n";
}

void writeAccuracySection(std::ostream& md, const FullRun& run)
{
	const auto& all = run.pairs;
	auto summarise = [&](const std::string& title, std::function<bool(const PairResult&)> in) {
		std::vector<PairResult> s;
		for (const auto& r : all)
			if (in(r)) s.push_back(r);
		if (s.empty()) return;
		size_t ok = 0, merged_wrong = 0, mrpt_ran = 0, mrpt_ok = 0;
		for (const auto& r : s)
		{
			ok += r.correct;
			merged_wrong += r.merged && !r.correct;
			mrpt_ran += r.mrpt_ran;
			mrpt_ok += r.mrpt_correct;
		}
		std::vector<PairResult> good;
		for (const auto& r : s)
			if (r.correct) good.push_back(r);
		md << "| " << title << " | " << ok << " / " << s.size() << " | " << merged_wrong << " | "
		   << num(median(column(good, [](auto& r) { return r.rmse; })), 3) << " | "
		   << num(median(column(s, [](auto& r) { return r.floor_rmse; })), 3) << " | "
		   << num(median(column(good, [](auto& r) { return r.yaw_err; })), 4) << " | "
		   << num(median(column(good, [](auto& r) { return r.scale_err_pct; })), 4) << " | "
		   << num(median(column(good, [](auto& r) { return r.implied_err_pct; })), 4) << " | "
		   << num(median(column(s, [](auto& r) { return r.seconds; })), 2) << " | "
		   << (mrpt_ran ? std::to_string(mrpt_ok) + " / " + std::to_string(s.size()) : "not run") << " |\n";
	};
	md << "## Success and accuracy (Table II / III analogue)\n\n"
	   << "Medians over the pairs that succeeded; runtime median over all pairs of the row. *TsICP from the "
		  "truth*: the RMSE TsICP converges to when started at the exact transform, over all pairs of the row: "
		  "what these renderings allow an edge-point registration.\n\n"
	   << "| pairs | ours: success | ours: merged but wrong | median RMSE [coarse cells] | TsICP from the truth "
		  "[coarse cells] | median yaw error [deg] | median scale error [%] | median implied-resolution error [%] | "
		  "median runtime [s] | MRPT: success |\n|---|---|---|---|---|---|---|---|---|---|\n";
	summarise("fr079, all resolution pairs (Fig. 8)", [](auto& r) { return r.set == "resolution"; });
	summarise("fr079, same resolution", [](auto& r) { return r.set == "resolution" && r.ref_res == r.other_res; });
	summarise("fr079, different resolutions", [](auto& r) { return r.set == "resolution" && r.ref_res != r.other_res; });
	summarise("fr079, ratio ≥ 4 (2↔8..10 cm)", [](auto& r) {
		return r.set == "resolution" && std::max(r.ref_res, r.other_res) / std::min(r.ref_res, r.other_res) >= 4 - 1e-9;
	});
	summarise("fr079, rotations (Fig. 9)", [](auto& r) { return r.set == "rotation"; });
	for (const auto& l : kLogs)
		summarise(l.name + " (2/5/10 cm)", [&](auto& r) { return r.set == "other-logs" && r.log == l.name; });
}

void writeRuntimeSection(std::ostream& md, const FullRun& run, const Facts& f)
{
	const auto& all = run.pairs;
	const auto& processes = run.processes;
	// Runtime ratio on the same-resolution pairs, pair by pair.
	md << "\n## Runtime against MRPT, same-resolution pairs (same run, same machine)\n\n"
	   << "| pair | ours [s] | MRPT [s] | ours / MRPT | ours ok | MRPT ok |\n|---|---|---|---|---|---|\n";
	for (const auto& r : all)
		if (isSameResolutionWithMrpt(r))
		{
			const double ratio = oursOverMrpt(r);
			md << "| " << cm(r.ref_res) << " cm | " << num(r.seconds, 2) << " | " << num(r.mrpt_seconds, 2) << " | "
			   << num(ratio, 2) << " | " << (r.correct ? "yes" : "no") << " | " << (r.mrpt_correct ? "yes" : "no")
			   << " |\n";
		}
	md << "\nMedian ratio ours/MRPT: **" << num(median(f.same_resolution_ratios), 2) << "**.\n";

	md << "\n### Whole process, same-resolution pairs\n\nEach side in a fresh process that loads the two "
		  "map_server files, aligns and exits (median of 3 runs, wall time).\n\n"
		  "| pair | ours [s] | MRPT [s] | ours / MRPT | ours: merged | MRPT: aligned | our peak RSS [MB] |\n"
		  "|---|---|---|---|---|---|---|\n";
	for (const auto& p : processes)
	{
		const double ratio = p.ours_s / std::max(1e-9, p.mrpt_s);
		md << "| " << cm(p.res) << " cm | " << num(p.ours_s, 2) << " | " << num(p.mrpt_s, 2) << " | " << num(ratio, 2)
		   << " | " << (p.ours_merged ? "yes" : "no") << " | " << (p.mrpt_aligned ? "yes" : "no") << " | "
		   << num(p.ours_peak_mb, 0) << " |\n";
	}

	// Alignment time distributions (in-process, `seconds` of each pair).
	md << "\n### Alignment time distribution (in-process)\n\n| pairs | median [s] | p95 [s] | max [s] |\n|---|---|---|---|\n";
	auto distribution = [&](const std::string& title, const std::vector<double>& v) {
		md << "| " << title << " | " << num(quantile(v, 0.5), 2) << " | " << num(quantile(v, 0.95), 2) << " | "
		   << num(quantile(v, 1.0), 2) << " |\n";
	};
	distribution("fr079 Fig. 8 (81 pairs)", f.fig8_secs);
	distribution("fr079 Fig. 9 (45 pairs)", f.fig9_secs);
	distribution("MRPT on the Fig. 8 pairs it aligns (same resolution)", f.mrpt_fig8_secs);
	distribution("Halmstad, every same-site sensor pair", f.halmstad_secs);
	size_t mrpt_refused = 0, mrpt_diff = 0;
	for (const auto& r : all)
		if (r.set == "resolution" && r.ref_res != r.other_res && r.mrpt_ran)
		{
			++mrpt_diff;
			mrpt_refused += !r.mrpt_correct;
		}
	if (mrpt_diff)
		md << "On the " << mrpt_diff << " different-resolution pairs MRPT failed " << mrpt_refused
		   << " (first reason: `"
		   << std::find_if(all.begin(), all.end(), [](auto& r) { return r.mrpt_ran && r.ref_res != r.other_res; })->mrpt_why
		   << "`).\n";
}

void writeMatrixOverlapAndStages(std::ostream& md, const FullRun& run)
{
	const auto& all = run.pairs;
	md << "\n## Matrices\n\n![ours](fig8_resolution_matrix_ours.png)\n\n![MRPT](fig8_resolution_matrix_mrpt.png)\n\n"
	   << "![rotations](fig9_rotation_matrix_ours.png)\n\nCells: RMSE in cells of the coarser map when merged "
		  "within 2 cells; `wrong` = reported merged but off; `no` = reported not merged.\n";

	md << "\n## Overlap: TsICP's ξ against the true overlap\n\n"
	   << "True overlap: share of the reference's edge points with an edge point of the other (true transform) "
		  "within one coarse cell. Median |ξ - true| over merged pairs: **"
	   << num(median(column(all, [](auto& r) { return r.merged ? std::abs(r.overlap - r.true_overlap) : NAN; })), 3)
	   << "** (median ξ " << num(median(column(all, [](auto& r) { return r.merged ? r.overlap : NAN; })), 3)
	   << ", median true " << num(median(column(all, [](auto& r) { return r.true_overlap; })), 3) << ").\n";

	md << "\n## Runtime per stage (medians over all pairs, seconds)\n\n| features | ransac | edges | icp | verify |\n|---|---|---|---|---|\n|";
	for (const char* k : {"features", "ransac", "edges", "icp", "verify"})
		md << " " << num(median(column(all, [&](auto& r) { return r.stages.count(k) ? r.stages.at(k) : NAN; })), 3) << " |";
	md << "\n";
}

void writeNegativesSection(std::ostream& md, const FullRun& run, const Facts& f)
{
	const auto& negatives = run.negatives;
	md << "\n## False merges (pairs that must not merge)\n\n| reference | other | kind | result | confidence |\n|---|---|---|---|---|\n";
	for (const auto& n : negatives)
	{
		md << "| " << n.a << " (5 cm) | " << n.b << " (8 cm) | " << n.what << " | "
		   << (n.merged ? "**MERGED (false)**" : "refused") << " | " << num(n.confidence, 2) << " |\n";
	}
	md << "\nFalse-merge rate: **" << f.false_merges << " / " << negatives.size() << "**.\n";
}

void writeHalmstadSection(std::ostream& md, const FullRun& run, const Facts& f)
{
	const auto &floor_plans = run.floor_plans;
	const auto& coarser = run.coarser;
	const auto& willow = run.willow;
	md << "\n## Real independent maps (Halmstad Robot Maps)\n\n"
	   << "Real sensor maps of four sites, each made in a separate session (`../shared/data/halmstad`), fed as "
		  "map_server files at 0.05 m. REF = the later map of each unordered same-site pair, OTHER = the earlier; "
		  "**right** = reported merged with the mean displacement of OTHER's occupied pixels against the annotated "
		  "similarity ≤ 40 px *and* the annotated inlier correspondences' RMS ≤ max(2 × the annotation's own "
		  "`rms_px`, 40 px). E5 and HIH are the calibration sites (the decision was tuned on them, "
		  "`decision-fit`); **F5 and KPT4A are the acceptance set: never tuned on**. "
		  "*Not merged right, from the annotation*: each such pair aligned again with the annotated similarity as "
		  "its first hypothesis, then the whole search (exhaustive: a start confident on its own does not stop it) "
		  "and the decision: merged right then, the search missed it; refused again, what its walls say is too "
		  "weak to merge on, or a placement elsewhere fits nearly as well.\n\n"
	   << "| site | role | pairs | merged right | refused | merged wrong | not merged right, from the annotation: merged right (search missed) | refused (weak evidence or a rival) | median displacement [px] | median corr. RMS [px] | median runtime [s] | MRPT (sample, 30 s limit) |\n"
	   << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
	for (const auto& site : {"E5", "HIH", "F5", "KPT4A"})
	{
		if (!f.sites.count(site)) continue;
		const HalmstadTally& r = f.sites.at(site);
		const bool cal = isCalibrationSite(site);
		md << "| " << site << " | " << (cal ? "calibration" : "**acceptance**") << " | " << r.pairs << " | "
		   << r.right << " (" << num(100.0 * r.right / std::max<size_t>(1, r.pairs), 0) << " %) | " << r.refused
		   << " | " << r.wrong << " | " << r.search_missed << " | " << r.evidence_weak << " | " << num(median(r.disp), 1) << " | " << num(median(r.corr), 1) << " | "
		   << num(median(r.secs), 2) << " | " << r.mrpt_right << " right of " << r.mrpt_ran << " ("
		   << r.mrpt_timeout << " timed out) |\n";
	}
	md << "\nCross-site negatives (a sensor map of one site against sensor maps of the others, 6 per map): **"
	   << f.cross_merged << " merged / " << f.cross << "**.\n";
	md << "\nWillow Garage, navstage 5 cm (REF) vs stageros 10 cm (two independent SLAM maps, one turned 90°): "
	   << (willow.success ? "merged" : "**not merged**") << ", x " << num(willow.metric.t.x(), 3) << " m, y "
	   << num(willow.metric.t.y(), 3) << " m, yaw " << num(willow.metric.yaw * 180 / M_PI, 2) << "°, scale "
	   << num(willow.metric.scale, 4) << ", confidence " << num(willow.confidence, 2)
	   << " (reference and tolerance: README, test_real_maps).\n";
	if (!floor_plans.empty()) writeFloorPlanSection(md, floor_plans);
	if (!coarser.empty()) writeCoarserSection(md, coarser);
	if (!run.partial.empty()) writePartialSection(md, run.partial);
	if (!run.ros_maps.empty()) writeRosMapsSection(md, run.ros_maps);
	if (!run.carpin.runs.empty()) writeCarpinSection(md, run.carpin);
}

void writeScalingSection(std::ostream& md, const FullRun& run)
{
	const auto& scaling = run.scaling;
	md << "\n## Scaling\n\nThe fr079 pair at finer and finer resolution, each map padded with unknown cells to a square "
	  "(the other at half the reference's resolution, rotated 30°), aligned in a fresh process.\n\n"
	  "*Whole process*: the child from start to exit (loading both `.gridmap` files, aligning, exiting).\n\n"
	  "| reference cells | other cells | alignment [s] | whole process [s] | peak RSS [MB] | merged |\n|---|---|---|---|---|---|\n";
	for (const auto& c : scaling)
		md << "| " << c.ref_w << "×" << c.ref_h << " (" << num(c.ref_res * 100, 2) << " cm) | "
		   << c.ref_w / 2 << "×" << c.ref_h / 2 << " | " << num(c.seconds, 2) << " | " << num(c.process_seconds, 2)
		   << " | " << num(c.peak_mb, 0) << " | " << (c.merged ? std::string("yes") : "no: " + c.message) << " |\n";
	std::vector<ScalingCase> aligned_cases;
	for (const auto& c : scaling)
		if (c.merged) aligned_cases.push_back(c);
	if (aligned_cases.size() >= 2)
	{
		const auto& a = aligned_cases.front();
		const auto& b = aligned_cases.back();
		const double dc = std::log(double(b.ref_w) * b.ref_h / (double(a.ref_w) * a.ref_h));
		md << "\nFitted growth between the smallest and largest case: runtime ∝ cells^"
		   << num(std::log(b.seconds / a.seconds) / dc, 2) << ", peak memory ∝ cells^"
		   << num(std::log(b.peak_mb / a.peak_mb) / dc, 2) << ".\n";
	}
	md << "\n![size](scaling_size.png)\n\n![ratio](scaling_ratio.png)\n";
}

void writeBasinSection(std::ostream& md, const FullRun& run)
{
	const auto &basin_same = run.basin_same, &basin_ratio = run.basin_ratio;
	auto basinShare = [](const std::vector<BasinCell>& b) {
		return std::count_if(b.begin(), b.end(), [](auto& c) { return c.converged; });
	};

	md << "\n## Basin of convergence of TsICP alone (Fig. 7 analogue)\n\n"
	   << "TsICP started from the truth rotated by Δθ and scaled by Δs about the other map's centre; converged = "
		  "edge-point RMSE ≤ 0.5 coarse cell afterwards. 5 vs 5 cm: "
	   << basinShare(basin_same) << " / " << basin_same.size() << " starts converge; 2 vs 10 cm: "
	   << basinShare(basin_ratio) << " / " << basin_ratio.size() << ".\n\n"
	   << "![basin](fig7_basin_5cm_5cm.png)\n\n![basin](fig7_basin_2cm_10cm.png)\n";
}

/** A row of the targets table. */
void targetRow(std::ostream& md, const std::string& what, const std::string& got, bool met)
{
	md << "| " << what << " | " << got << " | " << (met ? "yes" : "**no**") << " |\n";
}

/** The paper's matrices: every pair merged, accuracy, runtime against MRPT. */
void writeMatrixTargets(std::ostream& md, const FullRun& run, const Facts& f)
{
	const auto& all = run.pairs;
	auto target = [&md](const std::string& what, const std::string& got, bool met) { targetRow(md, what, got, met); };
	std::vector<PairResult> fig8, good8;
	for (const auto& r : all)
		if (r.set == "resolution" || r.set == "rotation")
		{
			fig8.push_back(r);
			if (r.correct) good8.push_back(r);
		}
	const size_t merged8 = good8.size();
	target("every fr079 pair of the resolution and rotation matrices merged", std::to_string(merged8) + " / " + std::to_string(fig8.size()), merged8 == fig8.size());
	const double m_rmse = median(column(good8, [](auto& r) { return r.rmse; }));
	const double m_yaw = median(column(good8, [](auto& r) { return r.yaw_err; }));
	const double m_scale = median(column(good8, [](auto& r) { return r.scale_err_pct; }));
	target("median point RMSE ≤ 0.15 coarse cell", num(m_rmse, 3), m_rmse <= 0.15);
	target("median yaw error ≤ 0.04°", num(m_yaw, 4) + "°", m_yaw <= 0.04);
	target("median scale error ≤ 0.05 %", num(m_scale, 4) + " %", m_scale <= 0.05);
	target("median runtime no slower than MRPT on same-resolution pairs (ratio ≤ 1)", num(median(f.same_resolution_ratios), 2),
		   median(f.same_resolution_ratios) <= 1);
	for (const std::string set : {"rotation", "other-logs"})
	{
		std::vector<double> e;
		for (const auto& r : all)
			if (r.set == set && r.correct) e.push_back(r.rmse);
		if (!e.empty())
			target("median point RMSE ≤ 0.15 coarse cell, " + set + " (map_server files)", num(median(e), 3),
				   median(e) <= 0.15);
	}
}

/** Fleets of fr079 robots, of Halmstad maps, and the live node. */
void writeFleetTargets(std::ostream& md, const FullRun& run)
{
	const auto& fleets = run.fleets;
	const auto& halmstad_fleets = run.halmstad_fleets;
	const auto& live = run.live;
	auto target = [&md](const std::string& what, const std::string& got, bool met) { targetRow(md, what, got, met); };
	for (const auto& c : fleets)
	{
		if (c.name.find("another building") != std::string::npos)
			target("fleet " + c.name + ": every robot of the building placed within 2 cells, the other kept out",
				   std::to_string(c.placed_right) + " / " + std::to_string(c.building) + ", other placed: " +
					   std::to_string(c.others_placed),
				   c.placed_right == c.building && c.others_placed == 0);
		if (c.name.find("1000×1000") != std::string::npos)
			target("fleet of 8 maps of 1000×1000 cells in ≤ 3 s on 2 cores", num(c.seconds, 1) + " s", c.seconds <= 3);
	}
	for (const auto& h : halmstad_fleets)
	{
		const std::string name = "Halmstad fleet " + h.site + (h.mixed_cells ? " (mixed cells)" : "");
		if (h.maps >= 14)
			target(name + " of " + std::to_string(h.maps) + " maps in one call: ≤ 10 s, ≤ 2 GiB peak",
				   num(h.seconds, 1) + " s, " + num(h.peak_mb, 0) + " MB", h.seconds <= 10 && h.peak_mb <= 2048);
		const auto& d = h.joint.displacement_px;
		const double med = median(d), worst = d.empty() ? NAN : *std::max_element(d.begin(), d.end());
		target(name + ": every map placed right, displacement median ≤ 7 px, max ≤ 15 px",
			   std::to_string(h.joint.right) + " / " + std::to_string(h.maps - 1) + ", median " + num(med, 1) +
				   " px, max " + num(worst, 1) + " px",
			   h.joint.right + 1 == h.maps && med <= 7 && worst <= 15);
	}
	{
		const double worst = live.maxLatencySeconds();
		target("live node: merged map and TF within two estimation periods of the maps overlapping (simulated "
			   "clock, estimations as slow as measured; never wrong, the other building kept out)",
			   (worst < 0 ? std::string("a robot never published") : "latency max " + num(worst, 1) + " s") + " of " +
				   num(2 * live.period_s, 1) + " s; estimations median " + num(live.medianEstimateSeconds(), 2) +
				   " s, max " + num(live.maxEstimateSeconds(), 2) + " s",
			   live.met());
	}
}

/** Speed and memory (issue 12). */
void writeSpeedTargets(std::ostream& md, const BenchContext& ctx, const FullRun& run, const Facts& f)
{
	const auto& processes = run.processes;
	const auto& scaling = run.scaling;
	auto target = [&md](const std::string& what, const std::string& got, bool met) { targetRow(md, what, got, met); };
	target("whole process ≤ 1.0× MRPT on every same-resolution fr079 pair", "worst " + num(f.worst_process_ratio, 2) + "×",
		   !processes.empty() && f.worst_process_ratio <= 1.0);
	const double m8 = quantile(f.fig8_secs, 0.5), mm = quantile(f.mrpt_fig8_secs, 0.5), max8 = quantile(f.fig8_secs, 1.0);
	target("Fig. 8 alignment time: median ≤ 1.3× MRPT's median, max ≤ 1.5 s",
		   num(m8, 2) + " s vs MRPT " + num(mm, 2) + " s, max " + num(max8, 2) + " s", m8 <= 1.3 * mm && max8 <= 1.5);
	if (!ctx.quick)
		target("Halmstad pairs: median alignment time ≤ 0.4 s", num(quantile(f.halmstad_secs, 0.5), 2) + " s",
			   quantile(f.halmstad_secs, 0.5) <= 0.4);
	for (const auto& c : scaling)
	{
		if (c.cells == 4000)
			target("4000×4000 in ≤ 3 s with peak RSS ≤ 1 GiB", num(c.seconds, 2) + " s, " + num(c.peak_mb, 0) + " MB",
				   c.merged && c.seconds <= 3 && c.peak_mb <= 1024);
		if (c.cells == 8000)
			target("8000×8000 aligns or is refused clearly within 4 GiB",
				   (c.merged ? "aligned" : "refused (" + c.message.substr(0, 40) + "…)") + std::string(", ") +
					   num(c.peak_mb, 0) + " MB",
				   (c.merged || c.message.find("too large") != std::string::npos) && c.peak_mb <= 4096);
	}
}

/** Real independent maps: Halmstad sensor pairs, floor plans, OTHER recorded coarser, the ROS maps. */
void writeRealMapTargets(std::ostream& md, const FullRun& run, const Facts& f)
{
	const auto &floor_plans = run.floor_plans;
	const auto& coarser = run.coarser;
	auto target = [&md](const std::string& what, const std::string& got, bool met) { targetRow(md, what, got, met); };
	target("Halmstad F5 + KPT4A (acceptance) ≥ 95 % merged right",
		   std::to_string(f.acceptance_right) + " / " + std::to_string(f.acceptance_pairs),
		   f.acceptance_right >= 0.95 * f.acceptance_pairs);
	target("Halmstad E5 + HIH ≥ 90 % merged right", std::to_string(f.calibration_right) + " / " + std::to_string(f.calibration_pairs),
		   f.calibration_right >= 0.9 * f.calibration_pairs);
	target("0 merged wrong over all Halmstad sensor pairs and cross-site negatives",
		   std::to_string(f.halmstad_wrong + f.cross_merged), f.halmstad_wrong + f.cross_merged == 0);
	target("Halmstad runtime per pair no worse than before (median 1.1 s)", num(median(f.halmstad_secs), 2) + " s",
		   median(f.halmstad_secs) <= 1.1);
	const FloorPlanTotals plans = floorPlanTotals(floor_plans);
	target("floor plans F5 + KPT4A (acceptance) ≥ 17 / 18 merged right",
		   std::to_string(plans.acceptance_right) + " / " + std::to_string(plans.acceptance_pairs),
		   plans.acceptance_right >= 17);
	target("floor plans E5 + HIH ≥ 16 / 18 merged right",
		   std::to_string(plans.calibration_right) + " / " + std::to_string(plans.calibration_pairs),
		   plans.calibration_right >= 16);
	for (const auto& [factor, share] : {std::pair{kCoarserFactors[0], 0.95}, std::pair{kCoarserFactors[1], 0.9}})
	{
		const CoarserTotals acc = coarserTotals(coarser, factor, false), cal = coarserTotals(coarser, factor, true);
		target("OTHER " + num(factor, 1) + "× coarser, F5 + KPT4A ≥ " + num(100 * share, 0) + " % merged right, 0 wrong",
			   std::to_string(acc.right) + " / " + std::to_string(acc.pairs) + ", " +
				   std::to_string(acc.wrong + cal.wrong) + " wrong (E5 + HIH " + std::to_string(cal.right) +
				   " / " + std::to_string(cal.pairs) + ")",
			   acc.right >= share * acc.pairs && acc.wrong + cal.wrong == 0);
	}
	target("0 merged wrong over floor plans: own plan and every other site's",
		   std::to_string(plans.merged_wrong + plans.negatives_merged) + " (of " +
			   std::to_string(plans.negatives) + " negatives)",
		   plans.merged_wrong + plans.negatives_merged == 0);
	size_t ros_wrong = 0, ros_negatives = 0;
	for (const auto& r : run.ros_maps) ros_wrong += r.merged && !r.right, ros_negatives += !r.positive;
	target("0 merged wrong over the independent ROS maps, as filed and " + rosCellsLabel(kRosFinerFactor) +
			   ": same place and other places",
		   std::to_string(ros_wrong) + " (of " + std::to_string(run.ros_maps.size()) + " pairs, " +
			   std::to_string(ros_negatives) + " of different places)",
		   ros_wrong == 0);
	const PartialTotals partial = partialTotals(run.partial);
	target("0 merged wrong over partial maps (halves of the Halmstad sensor maps): same site and other sites",
		   std::to_string(partial.wrong + partial.negatives_merged) + " (of " +
			   std::to_string(partial.positives + partial.negatives) + " pairs, " +
			   std::to_string(partial.negatives) + " of other sites)",
		   partial.wrong + partial.negatives_merged == 0);
	target("0 merged wrong over Carpin's maps (never tuned on): same place and other places",
		   std::to_string(carpinWrongMerges(run.carpin)) + " (of " + std::to_string(run.carpin.runs.size()) + " pairs)",
		   carpinWrongMerges(run.carpin) == 0);
}

void writeTargets(std::ostream& md, const BenchContext& ctx, const FullRun& run, const Facts& f)
{
	md << "\n## Targets\n\n| target | this run | met |\n|---|---|---|\n";
	writeMatrixTargets(md, run, f);
	writeFleetTargets(md, run);
	writeSpeedTargets(md, ctx, run, f);
	targetRow(md, "zero false merges", std::to_string(f.false_merges) + " / " + std::to_string(run.negatives.size()),
		   f.false_merges == 0);
	if (!ctx.quick) writeRealMapTargets(md, run, f);
}

}  // namespace

void writeReport(const BenchContext& ctx, const std::string& out, const FullRun& run)
{
	writeCsv(out + "/pairs.csv", run.pairs);
	writeMatrixFigures(out, run);
	writeBasinFigures(out, run);
	writeScalingFigures(out, run);
	const Facts f = factsOf(run);
	std::ofstream md(out + "/REPORT.md");
	writeProtocol(md, ctx, out, run);
	writeAccuracySection(md, run);
	writeRuntimeSection(md, run, f);
	writeMatrixOverlapAndStages(md, run);
	writeNegativesSection(md, run, f);
	writeHalmstadSection(md, run, f);
	writeScalingSection(md, run);
	writeFleetSection(md, run.fleets);
	if (!run.halmstad_fleets.empty()) writeHalmstadFleetSection(md, run.halmstad_fleets, ctx.fleet.resolvedFor(ctx.options.decision));
	writeLiveSection(md, run.live);
	writeBasinSection(md, run);
	writeTargets(md, ctx, run, f);
}

}  // namespace multires_bench
