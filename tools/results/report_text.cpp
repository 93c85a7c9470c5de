// Report helpers shared by the sections of RESULTS.md (report_text.h).
#include "report_text.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "markdown.h"

namespace animorder::results {
namespace {

const std::vector<std::string> kMethodOrder = {"original", "static-sander07", "static-nehab06", "tipsify-per-frame",
                                               "meshopt",  "single",          "joint",          "oracle"};

size_t method_rank(const std::string& name) {
    const auto it = std::find(kMethodOrder.begin(), kMethodOrder.end(), name);
    return size_t(it - kMethodOrder.begin());
}

}  // namespace

std::vector<const Method*> methods_in_order(const Report& r) {
    std::vector<const Method*> ordered;
    for (const Method& m : r.methods) ordered.push_back(&m);
    std::stable_sort(ordered.begin(), ordered.end(),
                     [](const Method* a, const Method* b) { return method_rank(a->name) < method_rank(b->name); });
    return ordered;
}

std::vector<std::string> method_names(const std::vector<const Report*>& reports) {
    std::vector<std::string> names;
    for (const Report* r : reports)
        for (const Method& m : r->methods)
            if (std::find(names.begin(), names.end(), m.name) == names.end()) names.push_back(m.name);
    std::stable_sort(names.begin(), names.end(),
                     [](const std::string& a, const std::string& b) { return method_rank(a) < method_rank(b); });
    return names;
}

Varies varies(const Report& r) {
    std::set<long long> k, v;
    for (const Method& m : r.methods) {
        if (m.clusters >= 0) k.insert(m.clusters);
        if (m.views >= 0) v.insert(m.views);
    }
    return {k.size() > 1, v.size() > 1};
}

std::string method_label(const Method& m, const Varies& v, bool with_lambda) {
    std::string s = m.name;
    if (with_lambda && std::isfinite(m.lambda)) s += " λ=" + lambda_text(m.lambda);
    if (v.clusters && m.clusters >= 0) s += " k=" + std::to_string(m.clusters);
    if (v.views && m.views >= 0) s += " views=" + std::to_string(m.views);
    return s;
}

const Method* find_method(const Report& r, const std::string& name, double lambda) {
    const Method* best = nullptr;
    for (const Method& m : r.methods) {
        if (m.name != name) continue;
        if (std::isfinite(m.lambda) && std::isfinite(lambda) && !same_lambda(m.lambda, lambda)) continue;
        if (std::isfinite(m.lambda) && !std::isfinite(lambda)) continue;
        const bool preferred = (m.clusters < 0 || m.clusters == 5) && (m.views < 0 || m.views == 162);
        if (!best ||
            (preferred && !((best->clusters < 0 || best->clusters == 5) && (best->views < 0 || best->views == 162))))
            best = &m;
    }
    return best;
}

const Method* find_method_any(const Report& r, const std::string& name, double lambda) {
    const Method* m = find_method(r, name, lambda);
    return m ? m : find_method(r, name, kNaN);
}

std::string keyframes_total(const Report& r) {
    long long k = 0;
    for (const Clip& c : r.clips) k += c.keyframes;
    return std::to_string(k);
}

std::string clip_list(const Report& r) {
    std::string s;
    for (size_t i = 0; i < r.clips.size(); ++i)
        s += (i ? ", " : "") + r.clips[i].name + " (" + std::to_string(r.clips[i].keyframes) + ")";
    return s.empty() ? kDash : s;
}

std::string joined(const std::vector<long long>& v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
    return s;
}

std::string lambdas_joined(const std::vector<double>& v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + lambda_text(v[i]);
    return s;
}

std::string protocol(const Report& r) {
    std::string s = "`" + r.input + "`, " + count(r.triangles) + " triangles, " + std::to_string(r.clips.size()) +
                    (r.clips.size() == 1 ? " clip" : " clips") + " (" + keyframes_total(r) +
                    " keyframes); evaluation " + count(r.eval_views) + " random views × " + count(r.eval_resolution) +
                    "², seed " + count(r.eval_seed);
    if (r.nodes >= 0) s += ", " + std::to_string(r.nodes) + " nodes";
    s += "; clustering " + (r.views.empty() ? std::string(kDash) : joined(r.views)) + " views at " +
         count(r.resolution) + "², seed " + count(r.seed);
    if (!r.clusters.empty()) s += ", k " + joined(r.clusters);
    if (!r.lambdas.empty()) s += ", λ " + lambdas_joined(r.lambdas);
    s += "; FIFO cache " + count(r.cache_size) + "; " + count(r.threads) + " threads";
    if (std::isfinite(r.t_total)) s += "; run time " + f1(r.t_total / 60.0) + " min";
    return s + ".";
}

std::string compact_table(const Report& r) {
    const Varies v = varies(r);
    std::vector<std::vector<std::string>> rows;
    for (const Method& m : r.methods)
        rows.push_back({method_label(m, v, false), lambda_text(m.lambda), std::to_string(m.buffers), f3(m.acmr),
                        f3(m.atvr), f3(m.ovr_mean), f3(m.ovr_pooled), f1(m.time_s)});
    return table({"method", "λ", "buffers", "ACMR", "ATVR", "OVR mean", "OVR pooled", "preprocessing s"}, rows);
}

}  // namespace animorder::results
