// RESULTS.md's "Measured cluster orders (beyond the paper)": issue 15's `measured` and
// `measured-joint` (k-means whose cluster orders come from the overdraw graph measured over each
// cluster's nodes) against `single` and `joint` from the same runs (same nodes, same bootstrap),
// from measured/*.json:
//   measured/ganfaul-idle.json   Table 1's setting on Idle: OVR, ACMR, preprocessing time and its
//                                stages, against the goals
//   measured/sweep-k.json        OVR and index-buffer bytes against k (measured-k-ovr.svg,
//                                measured-k-bytes.svg), k = 1 against static-nehab06
//   measured/ganfaul-clips.json  every Ganfaul clip: single, joint, measured, measured-joint
//   measured/<character>.json    every other character: single against measured at each λ
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "markdown.h"
#include "report_text.h"
#include "sections.h"

namespace animorder::results {
namespace {

namespace fs = std::filesystem;

// The goals (issue 15, Ganfaul, k = 5).
constexpr double kIdleOvrGoal085 = 1.06, kIdleAcmrGoal085 = 0.95, kIdleOvrGoal3 = 1.012;
constexpr double kClipsOvrGoal = 1.08, kClipsJointOvrGoal = 1.09;
constexpr double kTimeRatioGoal = 2.0, kAcmrTolerance = 0.02;
// Issue 46's goals for making `measured` the default, per character × λ row: preprocessing time
// and peak memory against `single`'s in the same run.
constexpr double kDefaultTimeGoal = 2.0, kDefaultMemoryGoal = 1.5;

// The row of `name` at λ and k (λ NaN: the row without λ; k < 0: any k, 5 preferred).
const Method* row(const Report& r, const std::string& name, double lambda, long long k = -1) {
    if (k < 0) return std::isfinite(lambda) ? find_method(r, name, lambda) : find_method(r, name, kNaN);
    for (const Method& m : r.methods)
        if (m.name == name && m.clusters == k && (std::isfinite(lambda) ? same_lambda(m.lambda, lambda) : true))
            return &m;
    return nullptr;
}

std::string ratio_text(double a, double b) {
    return std::isfinite(a) && std::isfinite(b) && b > 0 ? format_fixed(a / b, 2) + "×" : kDash;
}

std::string verdict(bool met) { return met ? "met" : "**not met**"; }

// The process's peak resident memory while the method ran, in MB (evaluate's peak_rss_bytes).
std::string megabytes_text(const Method& m) {
    return std::isfinite(m.peak_rss_bytes) ? format_fixed(m.peak_rss_bytes / 1048576.0, 0) : kDash;
}

// Bytes of the index buffers of a method row: buffers × 3 indices × triangles, 16-bit indices when
// every vertex index fits below 65,535 (the primitive-restart value), 32-bit otherwise.
double index_bytes(const Report& r, const Method& m) {
    if (r.triangles < 0 || r.vertices < 0) return kNaN;
    return double(m.buffers) * 3.0 * double(r.triangles) * (r.vertices < 65535 ? 2.0 : 4.0);
}

std::string stages_text(const Method& m) {
    std::string s;
    for (const char* stage : {"patches", "rasterization", "assignment", "update"}) {
        const auto it = m.stages.find(stage);
        if (it == m.stages.end()) continue;
        if (!s.empty()) s += ", ";
        s += std::string(stage) + " " + f1(it->second);
    }
    return s.empty() ? kDash : s;
}

// A part's heading and its report; a part whose report is missing says so and ends there.
const Report* open_part(const Inputs& in, const char* heading, const char* file, std::string& b) {
    b += std::string("### ") + heading + "\n\n";
    const Report* r = report_or_not_run(in, file, b);
    if (!r) b += "\n";
    return r;
}

void idle_part(const Inputs& in, std::string& b) {
    const Report* r = open_part(in, "Table 1's setting: Ganfaul Idle", "measured/ganfaul-idle.json", b);
    if (!r) return;
    b += "`measured/ganfaul-idle.json`: " + protocol(*r) + " Goals (issue 15): at λ = 0.85 OVR ≤ " +
         format_fixed(kIdleOvrGoal085, 2) + " with ACMR ≤ " + format_fixed(kIdleAcmrGoal085, 2) + ", at λ = 3 OVR ≤ " +
         format_fixed(kIdleOvrGoal3, 3) + ", preprocessing at most " + format_fixed(kTimeRatioGoal, 0) +
         "× `single`'s. Seconds per stage are summed over the k-means iterations (the measured graphs and their "
         "orders are part of `update`).\n\n";
    std::vector<std::vector<std::string>> rows;
    for (const double lambda : {0.85, 3.0}) {
        const Method* s = row(*r, "single", lambda);
        const Method* m = row(*r, "measured", lambda);
        for (const Method* x : {s, m}) {
            if (!x) continue;
            std::string goal = kDash;
            if (x == m) {
                const bool ovr_met = lambda < 1 ? x->ovr_mean <= kIdleOvrGoal085 : x->ovr_mean <= kIdleOvrGoal3;
                const bool acmr_met = lambda < 1 ? x->acmr <= kIdleAcmrGoal085 : true;
                const bool time_met = s && x->time_s <= kTimeRatioGoal * s->time_s;
                goal = "OVR " + verdict(ovr_met) + (lambda < 1 ? ", ACMR " + verdict(acmr_met) : "") + ", time " +
                       verdict(time_met);
            }
            rows.push_back({x->name, lambda_text(lambda), "k=" + std::to_string(x->clusters), goal, stages_text(*x),
                            f3(x->acmr), f3(x->ovr_mean), f3(x->ovr_pooled), f1(x->time_s),
                            x == m && s ? ratio_text(x->time_s, s->time_s) : kDash, megabytes_text(*x),
                            x == m && s ? ratio_text(x->peak_rss_bytes, s->peak_rss_bytes) : kDash});
        }
    }
    if (const Report* idle = in.get("ganfaul-idle.json"))
        if (const Method* o = row(*idle, "oracle", 0.85))
            rows.push_back({"oracle (per node, ganfaul-idle.json)", "0.85", kDash, kDash, kDash, f3(o->acmr),
                            f3(o->ovr_mean), f3(o->ovr_pooled), f1(o->time_s), kDash, kDash, kDash});
    b += table({"method", "λ", "k", "goal", "stages s", "ACMR", "OVR", "OVR pooled", "preprocessing s",
                "time / single", "peak MB", "memory / single"},
               rows, 5) +
         "\n";
}

void sweep_part(const Inputs& in, Charts& charts, std::string& b) {
    const Report* r = open_part(in, "The curve to choose from: k against overdraw and index-buffer bytes",
                                "measured/sweep-k.json", b);
    if (!r) return;
    std::set<long long> ks;
    for (const Method& m : r->methods)
        if ((m.name == "single" || m.name == "measured") && m.clusters > 0) ks.insert(m.clusters);
    const bool sixteen_bit = r->vertices >= 0 && r->vertices < 65535;
    b += "`measured/sweep-k.json`: " + protocol(*r) + " Index-buffer bytes: buffers × 3 × triangles × " +
         (sixteen_bit ? "2 (16-bit indices)" : "4 (32-bit indices)") +
         ", what the k orders of one clip take; static-nehab06 is one buffer learnt from the first keyframe.\n\n";
    std::vector<std::vector<std::string>> rows;
    LineChart ovr, bytes;
    ovr.title = "Overdraw against k: single and measured (Ganfaul Idle)";
    ovr.x_label = "clusters k (index buffers per clip)";
    ovr.y_label = "OVR (mean)";
    ovr.min_y_span = 0.05;
    bytes.title = "Overdraw against index-buffer size (Ganfaul Idle)";
    bytes.x_label = "index buffers of the clip, KiB";
    bytes.y_label = "OVR (mean)";
    bytes.min_y_span = 0.05;
    for (const char* name : {"single", "measured"}) {
        LineSeries a{name, {}, {}}, c{name, {}, {}};
        for (const long long k : ks) {
            const Method* m = row(*r, name, kNaN, k);
            if (!m) continue;
            a.x.push_back(double(k));
            a.y.push_back(m->ovr_mean);
            c.x.push_back(index_bytes(*r, *m) / 1024.0);
            c.y.push_back(m->ovr_mean);
        }
        ovr.series.push_back(a);
        bytes.series.push_back(c);
    }
    for (const long long k : ks) ovr.x_ticks.push_back(double(k));
    const Method* nehab = row(*r, "static-nehab06", kNaN);
    if (nehab && !ks.empty()) {
        const double x0 = double(*ks.begin()), x1 = double(*ks.rbegin());
        ovr.series.push_back({"static-nehab06 (reference)", {x0, x1}, {nehab->ovr_mean, nehab->ovr_mean}, true, false});
        const double b1 = index_bytes(*r, *nehab) / 1024.0;
        bytes.series.push_back({"static-nehab06", {b1}, {nehab->ovr_mean}, false, true});
    }
    for (const long long k : ks) {
        const Method* s = row(*r, "single", kNaN, k);
        const Method* m = row(*r, "measured", kNaN, k);
        const Method* any = s ? s : m;
        rows.push_back({std::to_string(k), any ? count(any->buffers) : kDash,
                        any ? count((long long)index_bytes(*r, *any)) : kDash, s ? f3(s->ovr_mean) : kDash,
                        m ? f3(m->ovr_mean) : kDash, s ? f3(s->acmr) : kDash, m ? f3(m->acmr) : kDash,
                        s ? f1(s->time_s) : kDash, m ? f1(m->time_s) : kDash});
    }
    b += charts.chart("measured-k-ovr.svg", ovr, "OVR against k for single and measured");
    b += charts.chart("measured-k-bytes.svg", bytes, "OVR against index-buffer bytes for single and measured");
    b += "\n" +
         table({"k", "buffers", "index bytes", "single OVR", "measured OVR", "single ACMR", "measured ACMR", "single s",
                "measured s"},
               rows) +
         "\n";
    if (nehab) {
        const Method* m1 = row(*r, "measured", kNaN, 1);
        if (m1)
            b += "One buffer: `measured` k = 1 (learnt over every keyframe of the clip) reaches OVR " +
                 f3(m1->ovr_mean) + " (ACMR " + f3(m1->acmr) + ", " + f1(m1->time_s) +
                 " s) against `static-nehab06`'s " + f3(nehab->ovr_mean) + " (one keyframe; ACMR " + f3(nehab->acmr) +
                 ", " + f1(nehab->time_s) + " s, " + count((long long)index_bytes(*r, *nehab)) +
                 " index bytes): " + (m1->ovr_mean < nehab->ovr_mean ? "better" : "**not better**") + ".\n\n";
    }
}

void clips_part(const Inputs& in, std::string& b) {
    const Report* r = open_part(in, "Every Ganfaul clip", "measured/ganfaul-clips.json", b);
    if (!r) return;
    b += "`measured/ganfaul-clips.json`: " + protocol(*r) + " Goals (issue 15, λ = 0.85): `measured` OVR ≤ " +
         format_fixed(kClipsOvrGoal, 2) + ", `measured-joint` ≤ " + format_fixed(kClipsJointOvrGoal, 2) + ".\n\n";
    const char* const names[] = {"single", "joint", "measured", "measured-joint"};
    std::vector<std::vector<std::string>> rows;
    for (const double lambda : r->lambdas) {
        for (const char* name : names) {
            const Method* m = row(*r, name, lambda);
            if (!m) continue;
            std::string goal = kDash;
            if (std::string(name) == "measured" && same_lambda(lambda, 0.85))
                goal = verdict(m->ovr_mean <= kClipsOvrGoal);
            if (std::string(name) == "measured-joint" && same_lambda(lambda, 0.85))
                goal = verdict(m->ovr_mean <= kClipsJointOvrGoal);
            rows.push_back({name, lambda_text(lambda), goal, count(m->buffers), f3(m->acmr), f3(m->ovr_mean),
                            f3(m->ovr_pooled), f1(m->time_s)});
        }
    }
    b += table({"method", "λ", "goal", "buffers", "ACMR", "OVR", "OVR pooled", "preprocessing s"}, rows, 3) + "\n";
    // Per clip, λ = 0.85 (or the report's first λ).
    const double lambda = r->lambdas.empty() ? 0.85 : r->lambdas.front();
    std::vector<std::string> header = {"clip", "keyframes"};
    std::vector<const Method*> ms;
    for (const char* name : names)
        if (const Method* m = row(*r, name, lambda)) {
            ms.push_back(m);
            header.push_back(std::string(name) + " OVR");
        }
    std::vector<std::vector<std::string>> per;
    for (const Clip& c : r->clips) {
        std::vector<std::string> cells = {c.name, count(c.keyframes)};
        for (const Method* m : ms) {
            std::string cell = kDash;
            for (const ClipResult& cr : m->per_clip)
                if (cr.clip == c.name) cell = f3(cr.ovr_mean);
            cells.push_back(cell);
        }
        per.push_back(cells);
    }
    b += "Per clip at λ = " + lambda_text(lambda) + ":\n\n" + table(header, per, 1) + "\n";
}

void characters_part(const Inputs& in, std::string& b) {
    b += "### Every other skinned character\n\n";
    if (in.measured_characters.empty()) {
        b += not_run("measured/<character>.json") + "\n";
        return;
    }
    b += "One `animorder evaluate` run per character (`measured/<character>.json`, every clip, `single` and "
         "`measured` in the same run, k = 5). Goal (issue 15): `measured`'s OVR ≤ `single`'s at the same λ and k, "
         "with ACMR within " +
         format_fixed(kAcmrTolerance, 2) +
         ". The goal column marks each row that misses it: **worse** where measured's OVR is above single's, "
         "**ACMR higher** where measured's ACMR exceeds single's by more than the tolerance; \"ACMR lower\" marks "
         "an ACMR more than the tolerance below single's (outside the goal's letter, but a gain). \"Time ×\" and "
         "\"memory ×\" are measured's preprocessing time and peak memory over single's.\n\n";
    std::vector<std::vector<std::string>> rows;
    size_t total = 0, ovr_met = 0, acmr_higher = 0, acmr_lower = 0, met = 0, default_met = 0, memory_known = 0;
    for (const std::string& file : in.measured_characters) {
        const Report& r = *in.get(file);
        const std::string character = fs::path(file).stem().string();
        for (const double lambda : r.lambdas) {
            const Method* s = row(r, "single", lambda);
            const Method* m = row(r, "measured", lambda);
            if (!s || !m) continue;
            const double d_ovr = m->ovr_mean - s->ovr_mean, d_acmr = m->acmr - s->acmr;
            std::vector<std::string> marks;
            if (d_ovr > 0) marks.push_back("**worse**");
            if (d_acmr > kAcmrTolerance) marks.push_back("**ACMR higher**");
            if (d_acmr < -kAcmrTolerance) marks.push_back("ACMR lower");
            ++total;
            ovr_met += d_ovr <= 0;
            acmr_higher += d_acmr > kAcmrTolerance;
            acmr_lower += d_acmr < -kAcmrTolerance;
            met += d_ovr <= 0 && d_acmr <= kAcmrTolerance;
            std::string mark;
            for (const std::string& x : marks) mark += (mark.empty() ? "" : ", ") + x;
            // Issue 46: OVR at or below single's, time and peak memory within the goals' ratios.
            const double time_ratio = m->time_s / s->time_s, memory_ratio = m->peak_rss_bytes / s->peak_rss_bytes;
            std::vector<std::string> misses;
            if (d_ovr > 0) misses.push_back("**OVR**");
            if (!(time_ratio <= kDefaultTimeGoal)) misses.push_back("**time**");
            if (!std::isfinite(memory_ratio))
                misses.push_back("memory not measured");
            else if (memory_ratio > kDefaultMemoryGoal)
                misses.push_back("**memory**");
            memory_known += std::isfinite(memory_ratio);
            default_met += misses.empty();
            std::string default_mark;
            for (const std::string& x : misses) default_mark += (default_mark.empty() ? "" : ", ") + x;
            rows.push_back({character, lambda_text(lambda), mark.empty() ? "met" : mark,
                            default_mark.empty() ? "met" : default_mark, count(r.triangles), keyframes_total(r),
                            f3(s->ovr_mean), f3(m->ovr_mean), format_fixed(d_ovr, 3), f3(s->acmr), f3(m->acmr),
                            format_fixed(d_acmr, 3), f1(s->time_s), f1(m->time_s), ratio_text(m->time_s, s->time_s),
                            ratio_text(m->peak_rss_bytes, s->peak_rss_bytes)});
        }
    }
    // The characters of "Every skinned character" (characters/*.json) that have no measured report.
    std::string missing;
    for (const std::string& file : in.characters) {
        const std::string character = fs::path(file).stem().string();
        if (!in.get("measured/" + character + ".json")) missing += (missing.empty() ? "" : ", ") + character;
    }
    b += table({"character", "λ", "goal", "default goals", "triangles", "keyframes", "single OVR", "measured OVR",
                "Δ OVR", "single ACMR", "measured ACMR", "Δ ACMR", "single s", "measured s", "time ×", "memory ×"},
               rows, 4) +
         "\n" + std::to_string(total) + " character × λ rows from " + std::to_string(in.measured_characters.size()) +
         " characters: measured's OVR ≤ single's in " + std::to_string(ovr_met) + "; ACMR more than " +
         format_fixed(kAcmrTolerance, 2) + " above single's in " + std::to_string(acmr_higher) + ", more than " +
         format_fixed(kAcmrTolerance, 2) + " below in " + std::to_string(acmr_lower) +
         "; both OVR and ACMR goals met "
         "(ACMR not higher by more than the tolerance) in " +
         std::to_string(met) + "." + (missing.empty() ? std::string() : " No measured report for " + missing + ".") +
         " Issue 46's goals for the default (\"default goals\": OVR ≤ single's, preprocessing time ≤ " +
         format_fixed(kDefaultTimeGoal, 0) + "× and peak memory ≤ " + format_fixed(kDefaultMemoryGoal, 1) +
         "× single's in the same run; memory is the process's peak resident size while the method ran, "
         "`peak_rss_bytes`) met in " +
         std::to_string(default_met) + " of " + std::to_string(total) + " rows; memory measured in " +
         std::to_string(memory_known) + ".\n\n";
}

}  // namespace

Section measured_section(const Inputs& in, Charts& charts) {
    Section s{"measured", "Measured cluster orders (beyond the paper)", ""};
    std::string& b = s.body;
    b += "`measured` is `single`'s k-means with one change in the update step: each cluster's buffer orders its "
         "λ patches by the overdraw graph measured over that cluster's own nodes (w(a→b) = fragments of b that "
         "pass the depth test and are later covered by a), a greedy Eades–Lin–Smyth feedback arc set improved by "
         "sifting that never raises the measured cost; `measured-joint` does the same for the joint set. Each "
         "report below runs `single` (and `joint`) beside it on the same nodes, so the differences are the "
         "orders alone.\n\n";
    idle_part(in, b);
    sweep_part(in, charts, b);
    clips_part(in, b);
    characters_part(in, b);
    while (b.size() >= 2 && b.compare(b.size() - 2, 2, "\n\n") == 0) b.pop_back();
    return s;
}

}  // namespace animorder::results
