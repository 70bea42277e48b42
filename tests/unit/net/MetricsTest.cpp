// MetricsRegistry: exact exposition text, escaping, number formatting, registration rules, threads.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "net/Metrics.h"

using gis::Labels;
using gis::MetricsRegistry;

TEST(Metrics, RendersExactExpositionText) {
    MetricsRegistry r;
    // Registered out of name order and with labels out of name order: the output must not care.
    r.gauge("gis_sessions_active", "Open sessions.").set(2);
    r.counter("gis_frames_total", "Frames rendered.", {{"technique", "rsm_gather"}, {"scene", "cornell"}})
        .inc(3);
    r.counter("gis_frames_total", "Frames rendered.", {{"technique", "ssbc"}, {"scene", "box"}}).inc();
    auto& h = r.histogram("gis_frame_ms", "Frame time in ms.", {1, 2.5, 10});
    for (double v : {0.5, 1.0, 3.0, 20.0}) h.observe(v);

    EXPECT_EQ(r.render(), "# HELP gis_frame_ms Frame time in ms.\n"
                          "# TYPE gis_frame_ms histogram\n"
                          "gis_frame_ms_bucket{le=\"1\"} 2\n"
                          "gis_frame_ms_bucket{le=\"2.5\"} 2\n"
                          "gis_frame_ms_bucket{le=\"10\"} 3\n"
                          "gis_frame_ms_bucket{le=\"+Inf\"} 4\n"
                          "gis_frame_ms_sum 24.5\n"
                          "gis_frame_ms_count 4\n"
                          "# HELP gis_frames_total Frames rendered.\n"
                          "# TYPE gis_frames_total counter\n"
                          "gis_frames_total{scene=\"box\",technique=\"ssbc\"} 1\n"
                          "gis_frames_total{scene=\"cornell\",technique=\"rsm_gather\"} 3\n"
                          "# HELP gis_sessions_active Open sessions.\n"
                          "# TYPE gis_sessions_active gauge\n"
                          "gis_sessions_active 2\n");
}

TEST(Metrics, HistogramLabelsComeBeforeLe) {
    MetricsRegistry r;
    r.histogram("lat", "L", {5}, {{"technique", "isr"}}).observe(7);
    EXPECT_EQ(r.render(), "# HELP lat L\n"
                          "# TYPE lat histogram\n"
                          "lat_bucket{technique=\"isr\",le=\"5\"} 0\n"
                          "lat_bucket{technique=\"isr\",le=\"+Inf\"} 1\n"
                          "lat_sum{technique=\"isr\"} 7\n"
                          "lat_count{technique=\"isr\"} 1\n");
}

TEST(Metrics, EscapesLabelValuesAndHelp) {
    MetricsRegistry r;
    r.counter("c", "Line one\nback\\slash \"quoted\"", {{"path", "a\"b\\c\nd"}}).inc();
    // Help escapes backslash and newline only; label values also escape the double quote.
    EXPECT_EQ(r.render(), "# HELP c Line one\\nback\\\\slash \"quoted\"\n"
                          "# TYPE c counter\n"
                          "c{path=\"a\\\"b\\\\c\\nd\"} 1\n");
}

TEST(Metrics, FormatsNumbersAsPrometheusParsesThem) {
    EXPECT_EQ(gis::formatMetricValue(3), "3");
    EXPECT_EQ(gis::formatMetricValue(-2), "-2");
    EXPECT_EQ(gis::formatMetricValue(1e6), "1000000");
    EXPECT_EQ(gis::formatMetricValue(123456789012.0), "123456789012");
    EXPECT_EQ(gis::formatMetricValue(0.0), "0");
    EXPECT_EQ(gis::formatMetricValue(-0.0), "0");
    EXPECT_EQ(gis::formatMetricValue(0.1), "0.1");
    EXPECT_EQ(gis::formatMetricValue(2.5e-7), "2.5e-07");
    EXPECT_EQ(gis::formatMetricValue(1e20), "1e+20");
    EXPECT_EQ(gis::formatMetricValue(std::numeric_limits<double>::infinity()), "+Inf");
    EXPECT_EQ(gis::formatMetricValue(-std::numeric_limits<double>::infinity()), "-Inf");
    EXPECT_EQ(gis::formatMetricValue(std::nan("")), "NaN");

    MetricsRegistry r;
    r.gauge("g", "G").set(std::nan(""));
    EXPECT_EQ(r.render(), "# HELP g G\n# TYPE g gauge\ng NaN\n");
}

TEST(Metrics, SameNameAndLabelsReturnSameObject) {
    MetricsRegistry r;
    auto& a = r.counter("requests_total", "R", {{"a", "1"}, {"b", "2"}});
    auto& b = r.counter("requests_total", "R", {{"b", "2"}, {"a", "1"}});
    auto& c = r.counter("requests_total", "R", {{"a", "1"}, {"b", "3"}});
    EXPECT_EQ(&a, &b);
    EXPECT_NE(&a, &c);
    // References stay valid while many more series are added.
    for (int i = 0; i < 1000; ++i) r.counter("requests_total", "R", {{"a", std::to_string(i)}});
    EXPECT_EQ(&a, &r.counter("requests_total", "R", {{"a", "1"}, {"b", "2"}}));
    EXPECT_EQ(&r.gauge("g", "G"), &r.gauge("g", "G"));
    EXPECT_EQ(&r.histogram("h", "H", {1, 2}), &r.histogram("h", "H", {1, 2}));
}

TEST(Metrics, ConflictingRegistrationIsAProgrammerError) {
    MetricsRegistry r;
    r.counter("x_total", "X");
    EXPECT_THROW(r.gauge("x_total", "X"), std::logic_error);
    EXPECT_THROW(r.counter("x_total", "other help"), std::logic_error);
    r.histogram("h", "H", {1, 2});
    EXPECT_THROW(r.histogram("h", "H", {1, 3}, {{"a", "b"}}), std::logic_error);
    EXPECT_THROW(r.counter("h_count", "C"), std::logic_error);
    r.gauge("q_sum", "Q");
    EXPECT_THROW(r.histogram("q", "Q", {1}), std::logic_error);
}

TEST(Metrics, ValidatesNames) {
    MetricsRegistry r;
    EXPECT_NO_THROW(r.counter("ns:sub_name_1", "ok", {{"_label9", "any value at all {}\""}}));
    for (const char* bad : {"", "1abc", "a-b", "a b", "é"})
        EXPECT_THROW(r.counter(bad, "h"), std::logic_error) << bad;
    for (const char* bad : {"", "1a", "a:b", "a-b", "__reserved"})
        EXPECT_THROW(r.counter("c", "h", {{bad, "v"}}), std::logic_error) << bad;
    EXPECT_THROW(r.counter("c", "h", {{"a", "1"}, {"a", "2"}}), std::logic_error);
    EXPECT_THROW(r.histogram("h", "h", {1}, {{"le", "1"}}), std::logic_error);
    EXPECT_NO_THROW(r.counter("c", "h", {{"le", "fine on a counter"}}));
}

TEST(Metrics, HistogramBucketsAreInclusiveAndValidated) {
    gis::Histogram h({1, 2, 4, std::numeric_limits<double>::infinity()});
    EXPECT_EQ(h.upperBounds(), (std::vector<double>{1, 2, 4}));
    for (double v : {-5.0, 1.0, 1.5, 2.0, 4.0, 4.0001, 1e9}) h.observe(v);
    auto s = h.snapshot();
    EXPECT_EQ(s.cumulative, (std::vector<std::uint64_t>{2, 4, 5, 7}));
    EXPECT_EQ(s.count, 7u);
    EXPECT_DOUBLE_EQ(s.sum, -5.0 + 1 + 1.5 + 2 + 4 + 4.0001 + 1e9);

    EXPECT_THROW(gis::Histogram({2, 1}), std::invalid_argument);
    EXPECT_THROW(gis::Histogram({1, 1}), std::invalid_argument);
    EXPECT_THROW(gis::Histogram({1, std::nan("")}), std::invalid_argument);
    EXPECT_NO_THROW(gis::Histogram({}));

    auto buckets = gis::defaultLatencyBucketsMs();
    ASSERT_FALSE(buckets.empty());
    EXPECT_NO_THROW(gis::Histogram{buckets});
}

#ifdef NDEBUG
TEST(Metrics, CounterIgnoresNegativeIncrementsInRelease) {
    gis::Counter c;
    c.inc(2);
    c.inc(-1);
    c.inc(std::nan(""));
    EXPECT_EQ(c.value(), 2);
}
#endif

TEST(Metrics, GaugeMovesBothWays) {
    gis::Gauge g;
    g.inc();
    g.inc(4);
    g.dec(2);
    EXPECT_EQ(g.value(), 3);
    g.set(-1.5);
    EXPECT_EQ(g.value(), -1.5);
}

TEST(Metrics, ConcurrentUpdatesFromEightThreadsSumExactly) {
    MetricsRegistry r;
    constexpr int kThreads = 8, kIters = 20000;
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&r, t] {
            // Every thread registers for itself, as render workers do: all must get the same objects.
            auto& c = r.counter("frames_total", "F", {{"scene", "cornell"}});
            auto& g = r.gauge("inflight", "I");
            auto& h = r.histogram("ms", "M", gis::defaultLatencyBucketsMs());
            for (int i = 0; i < kIters; ++i) {
                c.inc();
                g.inc();
                h.observe(static_cast<double>(i % 7));
                g.dec();
                if (t == 0 && i % 1000 == 0) (void)r.render(); // scrapes racing the updates
            }
        });
    }
    for (auto& t : threads) t.join();
    EXPECT_EQ(r.counter("frames_total", "F", {{"scene", "cornell"}}).value(), kThreads * kIters);
    EXPECT_EQ(r.gauge("inflight", "I").value(), 0);
    auto s = r.histogram("ms", "M", gis::defaultLatencyBucketsMs()).snapshot();
    EXPECT_EQ(s.count, std::uint64_t(kThreads) * kIters);
    EXPECT_EQ(s.cumulative.back(), s.count);
    double perThread = 0;
    for (int i = 0; i < kIters; ++i) perThread += i % 7;
    EXPECT_EQ(s.sum, perThread * kThreads);
    EXPECT_NE(r.render().find("frames_total{scene=\"cornell\"} 160000\n"), std::string::npos);
}
