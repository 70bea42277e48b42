// Prometheus registry: validation at registration, text exposition format 0.0.4 at scrape.
#include "net/Metrics.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace gis {

namespace {

bool isMetricName(const std::string& s) {
    if (s.empty()) return false;
    auto first = [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == ':';
    };
    if (!first(s[0])) return false;
    return std::all_of(s.begin() + 1, s.end(), [&](char c) { return first(c) || (c >= '0' && c <= '9'); });
}

bool isLabelName(const std::string& s) {
    if (s.empty()) return false;
    auto first = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
    if (!first(s[0])) return false;
    return std::all_of(s.begin() + 1, s.end(), [&](char c) { return first(c) || (c >= '0' && c <= '9'); });
}

// One canonical key per label set, so {a,b} and {b,a} are the same series and render identically.
Labels canonicalLabels(const std::string& metric, Labels labels, bool histogram) {
    std::sort(labels.begin(), labels.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (std::size_t i = 0; i < labels.size(); ++i) {
        const std::string& n = labels[i].first;
        if (!isLabelName(n))
            throw std::logic_error("metric '" + metric + "': invalid label name '" + n + "'");
        // "__" names are reserved for Prometheus itself; "le" is the bucket label we add.
        if (n.rfind("__", 0) == 0)
            throw std::logic_error("metric '" + metric + "': reserved label '" + n + "'");
        if (histogram && n == "le")
            throw std::logic_error("histogram '" + metric + "': label 'le' is reserved");
        if (i > 0 && labels[i - 1].first == n)
            throw std::logic_error("metric '" + metric + "': duplicate label '" + n + "'");
    }
    return labels;
}

std::string escapeHelp(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        if (c == '\\')
            out += "\\\\";
        else if (c == '\n')
            out += "\\n";
        else
            out += c;
    }
    return out;
}

std::string escapeLabelValue(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        if (c == '\\')
            out += "\\\\";
        else if (c == '"')
            out += "\\\"";
        else if (c == '\n')
            out += "\\n";
        else
            out += c;
    }
    return out;
}

// `{a="x",le="5"}`, or nothing when there are no labels at all.
std::string labelText(const Labels& labels, const std::string* le = nullptr) {
    if (labels.empty() && !le) return {};
    std::string out = "{";
    bool first = true;
    for (const auto& [n, v] : labels) {
        if (!first) out += ',';
        first = false;
        out += n + "=\"" + escapeLabelValue(v) + '"';
    }
    if (le) {
        if (!first) out += ',';
        out += "le=\"" + *le + '"';
    }
    out += '}';
    return out;
}

std::vector<double> validBuckets(std::vector<double> b) {
    if (!b.empty() && b.back() == INFINITY) b.pop_back();
    for (std::size_t i = 0; i < b.size(); ++i) {
        if (!std::isfinite(b[i])) throw std::invalid_argument("histogram bucket bounds must be finite");
        if (i > 0 && !(b[i] > b[i - 1]))
            throw std::invalid_argument("histogram bucket bounds must be strictly increasing");
    }
    return b;
}

const char* typeName(int t) {
    static const char* names[] = {"counter", "gauge", "histogram"};
    return names[t];
}

} // namespace

void Counter::inc(double v) {
    assert(v >= 0 && "Counter::inc with a negative or NaN increment");
    if (!(v >= 0)) return;
    mValue.fetch_add(v, std::memory_order_relaxed);
}

Histogram::Histogram(std::vector<double> upperBounds)
    : mBounds(validBuckets(std::move(upperBounds))), mCounts(mBounds.size() + 1, 0) {}

void Histogram::observe(double v) {
    assert(!std::isnan(v) && "Histogram::observe(NaN)");
    if (std::isnan(v)) return;
    // Buckets are "less than or equal": the first bound >= v is v's bucket.
    auto bucket =
        static_cast<std::size_t>(std::lower_bound(mBounds.begin(), mBounds.end(), v) - mBounds.begin());
    std::lock_guard lock(mMutex);
    ++mCounts[bucket];
    mSum += v;
    ++mCount;
}

Histogram::Snapshot Histogram::snapshot() const {
    Snapshot s;
    std::lock_guard lock(mMutex);
    s.cumulative.resize(mCounts.size());
    std::uint64_t running = 0;
    for (std::size_t i = 0; i < mCounts.size(); ++i) s.cumulative[i] = running += mCounts[i];
    s.sum = mSum;
    s.count = mCount;
    return s;
}

MetricsRegistry::Family& MetricsRegistry::family(const std::string& name, const std::string& help,
                                                 Type type) {
    if (!isMetricName(name)) throw std::logic_error("invalid metric name '" + name + "'");
    auto it = mFamilies.find(name);
    if (it != mFamilies.end()) {
        if (it->second.type != type)
            throw std::logic_error("metric '" + name + "' registered as " + typeName(int(it->second.type)) +
                                   " and " + typeName(int(type)));
        if (it->second.help != help)
            throw std::logic_error("metric '" + name + "' registered with two helps");
        return it->second;
    }
    // A histogram's samples are name_bucket/_sum/_count; another family by one of those names would
    // make the exposition ambiguous, so refuse it in either registration order.
    static const char* suffixes[] = {"_bucket", "_sum", "_count"};
    for (const char* sfx : suffixes) {
        if (type == Type::Histogram && mFamilies.count(name + sfx))
            throw std::logic_error("histogram '" + name + "' clashes with metric '" + name + sfx + "'");
        std::string_view s(sfx);
        if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0) {
            auto base = mFamilies.find(name.substr(0, name.size() - s.size()));
            if (base != mFamilies.end() && base->second.type == Type::Histogram)
                throw std::logic_error("metric '" + name + "' clashes with histogram '" + base->first + "'");
        }
    }
    return mFamilies.emplace(name, Family{type, help, {}, {}, {}, {}}).first->second;
}

Counter& MetricsRegistry::counter(const std::string& name, const std::string& help, const Labels& labels) {
    Labels key = canonicalLabels(name, labels, false);
    std::lock_guard lock(mMutex);
    auto& slot = family(name, help, Type::Counter).counters[std::move(key)];
    if (!slot) slot = std::make_unique<Counter>();
    return *slot;
}

Gauge& MetricsRegistry::gauge(const std::string& name, const std::string& help, const Labels& labels) {
    Labels key = canonicalLabels(name, labels, false);
    std::lock_guard lock(mMutex);
    auto& slot = family(name, help, Type::Gauge).gauges[std::move(key)];
    if (!slot) slot = std::make_unique<Gauge>();
    return *slot;
}

Histogram& MetricsRegistry::histogram(const std::string& name, const std::string& help,
                                      std::vector<double> buckets, const Labels& labels) {
    Labels key = canonicalLabels(name, labels, true);
    buckets = validBuckets(std::move(buckets));
    std::lock_guard lock(mMutex);
    Family& f = family(name, help, Type::Histogram);
    // Series of one family must share a layout, or rate()/histogram_quantile() across them is meaningless.
    if (f.histograms.empty())
        f.buckets = buckets;
    else if (f.buckets != buckets)
        throw std::logic_error("histogram '" + name + "' registered with two bucket layouts");
    auto& slot = f.histograms[std::move(key)];
    if (!slot) slot = std::make_unique<Histogram>(std::move(buckets));
    return *slot;
}

std::string MetricsRegistry::render() const {
    std::string out;
    std::lock_guard lock(mMutex);
    for (const auto& [name, f] : mFamilies) {
        out += "# HELP " + name;
        if (!f.help.empty()) out += ' ' + escapeHelp(f.help);
        out += "\n# TYPE " + name + ' ' + typeName(int(f.type)) + '\n';
        for (const auto& [labels, c] : f.counters)
            out += name + labelText(labels) + ' ' + formatMetricValue(c->value()) + '\n';
        for (const auto& [labels, g] : f.gauges)
            out += name + labelText(labels) + ' ' + formatMetricValue(g->value()) + '\n';
        for (const auto& [labels, h] : f.histograms) {
            Histogram::Snapshot s = h->snapshot();
            for (std::size_t i = 0; i < s.cumulative.size(); ++i) {
                std::string le = i < f.buckets.size() ? formatMetricValue(f.buckets[i]) : "+Inf";
                out += name + "_bucket" + labelText(labels, &le) + ' ' +
                       formatMetricValue(static_cast<double>(s.cumulative[i])) + '\n';
            }
            out += name + "_sum" + labelText(labels) + ' ' + formatMetricValue(s.sum) + '\n';
            out += name + "_count" + labelText(labels) + ' ' +
                   formatMetricValue(static_cast<double>(s.count)) + '\n';
        }
    }
    return out;
}

std::vector<double> defaultLatencyBucketsMs() {
    return {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000};
}

std::string formatMetricValue(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
    if (v == 0) return "0"; // also -0, which would print as "-0"
    // Below 2^53 every integral double is exact, so counters and bucket counts print as plain integers.
    if (std::fabs(v) < 9007199254740992.0 && std::trunc(v) == v)
        return std::to_string(static_cast<long long>(v));
    char buf[64];
    auto res = std::to_chars(buf, buf + sizeof buf, v); // shortest round-trip, e.g. 0.1, 1.5e-07, 1e+20
    return std::string(buf, res.ptr);
}

} // namespace gis
