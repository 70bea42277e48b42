// Owns the service's metrics: counters, gauges and histograms in one registry, rendered as Prometheus
// text exposition format 0.0.4 for the /metrics endpoint.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gis {

/// Label name/value pairs; the order given does not matter (the registry sorts them by name).
using Labels = std::vector<std::pair<std::string, std::string>>;

/// Content-Type for the /metrics response.
inline constexpr std::string_view kMetricsContentType = "text/plain; version=0.0.4; charset=utf-8";

/// A monotonically increasing value. inc() is lock-free, safe from any thread.
class Counter {
public:
    /// Negative or NaN increments are a caller bug: asserted in debug, ignored in release so the
    /// counter stays monotonic (Prometheus reads a decrease as a process restart).
    void inc(double v = 1);
    double value() const { return mValue.load(std::memory_order_relaxed); }

private:
    std::atomic<double> mValue{0};
};

/// A value that goes up and down. Lock-free, safe from any thread.
class Gauge {
public:
    void set(double v) { mValue.store(v, std::memory_order_relaxed); }
    void inc(double v = 1) { mValue.fetch_add(v, std::memory_order_relaxed); }
    void dec(double v = 1) { mValue.fetch_sub(v, std::memory_order_relaxed); }
    double value() const { return mValue.load(std::memory_order_relaxed); }

private:
    std::atomic<double> mValue{0};
};

/// Cumulative-bucket histogram. A per-histogram mutex (not atomics per field) so that a scrape
/// always sees _count equal to the +Inf bucket and a _sum that matches them.
class Histogram {
public:
    /// upperBounds: strictly increasing, finite; a trailing +Inf is accepted and dropped (the +Inf
    /// bucket is always present). Throws std::invalid_argument otherwise.
    explicit Histogram(std::vector<double> upperBounds);

    /// Counts v in every bucket with v <= bound. NaN is a caller bug: asserted in debug, dropped in
    /// release so one bad sample does not turn _sum into NaN forever.
    void observe(double v);

    struct Snapshot {
        std::vector<std::uint64_t> cumulative; ///< one per upper bound, then the +Inf bucket
        double sum = 0;
        std::uint64_t count = 0;
    };
    Snapshot snapshot() const;
    const std::vector<double>& upperBounds() const { return mBounds; }

private:
    std::vector<double> mBounds;
    mutable std::mutex mMutex;
    std::vector<std::uint64_t> mCounts; // per bucket, not cumulative; last is (bounds.back(), +Inf)
    double mSum = 0;
    std::uint64_t mCount = 0;
};

/// Registry of metric families. Registration takes the registry lock; the returned references stay
/// valid for the registry's lifetime, so hot paths keep them and never touch the registry again.
/// Misuse (invalid names, one name with two types, helps or bucket layouts, reserved label names,
/// duplicate label names) throws std::logic_error: these are programmer errors found at startup.
class MetricsRegistry {
public:
    MetricsRegistry() = default;
    MetricsRegistry(const MetricsRegistry&) = delete;
    MetricsRegistry& operator=(const MetricsRegistry&) = delete;

    Counter& counter(const std::string& name, const std::string& help, const Labels& labels = {});
    Gauge& gauge(const std::string& name, const std::string& help, const Labels& labels = {});
    Histogram& histogram(const std::string& name, const std::string& help, std::vector<double> buckets,
                         const Labels& labels = {});

    /// Exposition text: families sorted by name, series by their (name-sorted) labels.
    std::string render() const;

private:
    enum class Type { Counter, Gauge, Histogram };
    struct Family {
        Type type;
        std::string help;
        std::vector<double> buckets; // histograms only
        std::map<Labels, std::unique_ptr<Counter>> counters;
        std::map<Labels, std::unique_ptr<Gauge>> gauges;
        std::map<Labels, std::unique_ptr<Histogram>> histograms;
    };
    Family& family(const std::string& name, const std::string& help, Type type);

    mutable std::mutex mMutex;
    std::map<std::string, Family> mFamilies;
};

/// Render-latency buckets in milliseconds, 1 ms to 5 s.
std::vector<double> defaultLatencyBucketsMs();

/// A sample value as Prometheus parses it: integral values without exponent or fraction, "+Inf",
/// "-Inf", "NaN", anything else in the shortest form that round-trips.
std::string formatMetricValue(double v);

} // namespace gis
