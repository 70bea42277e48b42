// Frame publishing without a session: which region goes out, the binary message's header, the stats
// fields (checked against the protocol's stats schema) and the offer to each client.
#include <gtest/gtest.h>

#include "session/FramePublisher.h"
#include "session/ProtocolMessages.h"

namespace gis {
namespace {

std::shared_ptr<ClientLink> link(bool patches, int maxInFlight = 1) {
    return std::make_shared<ClientLink>(
        ClientRole::Controller, maxInFlight, [] {}, 64, patches);
}

std::vector<std::uint8_t> gradient(int w, int h) {
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4, 255);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            rgba[(static_cast<std::size_t>(y) * w + x) * 4] = static_cast<std::uint8_t>(x * 4);
    return rgba;
}

/// What the renderer's stats carry before publishing.
nlohmann::json rendererStats() {
    return {{"technique", "rsm_gather"},
            {"size", {64, 32}},
            {"frame_ms", 12.5},
            {"queue_ms", 0.5},
            {"passes", {{{"name", "gbuffer"}, {"gpu_ms", 2.0}}, {{"name", "gather"}, {"gpu_ms", 8.0}}}}};
}

std::uint16_t u16(const std::string& m, std::size_t at) {
    return static_cast<std::uint16_t>(static_cast<unsigned char>(m[at]) |
                                      (static_cast<unsigned char>(m[at + 1]) << 8));
}

TEST(FramePublisher, PatchesGoOnlyWhereEveryClientDrawsThem) {
    const TileRect tile{48, 16, 32, 32};
    EXPECT_FALSE(patchToSend(std::nullopt, 64, 32, {link(true)}));
    EXPECT_FALSE(patchToSend(tile, 64, 32, {})) << "nobody to send to";
    EXPECT_FALSE(patchToSend(tile, 64, 32, {link(true), link(false)})) << "one client draws whole images";
    const auto clipped = patchToSend(tile, 64, 32, {link(true), link(true)});
    ASSERT_TRUE(clipped);
    EXPECT_EQ(clipped->width, 16) << "clipped to the image";
    EXPECT_EQ(clipped->height, 16);
    EXPECT_FALSE(patchToSend(TileRect{64, 0, 16, 16}, 64, 32, {link(true)})) << "wholly outside";
}

TEST(FramePublisher, EncodesTheRegionWithItsSizeInTheHeader) {
    const auto rgba = gradient(64, 32);
    const EncodedFrame whole = encodeFrame(rgba, 64, 32, std::nullopt, ImageCodec::Png, 90, false, 7);
    EXPECT_EQ(whole.id, 7u);
    EXPECT_EQ(whole.message->substr(0, 4), "GIFR");
    EXPECT_EQ(u16(*whole.message, 8), 64);
    EXPECT_EQ(u16(*whole.message, 10), 32);
    EXPECT_EQ(static_cast<int>((*whole.message)[12]), static_cast<int>(ImageCodec::Png));
    const EncodedFrame patch =
        encodeFrame(rgba, 64, 32, TileRect{16, 8, 16, 8}, ImageCodec::Webp, 90, true, 8);
    EXPECT_EQ(patch.sentWidth, 16);
    EXPECT_EQ(u16(*patch.message, 8), 16);
    EXPECT_EQ(u16(*patch.message, 10), 8);
    EXPECT_EQ(patch.message->substr(kFrameHeaderSize + 12, 4), "VP8L") << "a snapshot is lossless";
    EXPECT_GE(whole.encodeMs, 0.0);
}

TEST(FramePublisher, StatsFollowTheProtocolsSchema) {
    const auto rgba = gradient(64, 32);
    const EncodedFrame patch =
        encodeFrame(rgba, 64, 32, TileRect{0, 0, 16, 16}, ImageCodec::Jpeg, 80, false, 3);
    nlohmann::json stats = rendererStats();
    addPublishingStats(stats, patch, "final", false, "builtin:cornell", 64, 32);
    EXPECT_EQ(stats["refined"], true);
    EXPECT_EQ(stats["bytes"], patch.message->size());
    EXPECT_EQ(stats["patch"]["width"], 16);
    EXPECT_EQ(stats["size"], nlohmann::json::array({64, 32})) << "the whole image's size";
    EXPECT_EQ(checkServerMessage(stats), "") << stats.dump();

    const FrameReport report = reportOf(stats, patch, "final", false);
    EXPECT_EQ(report.frameMs, 12.5);
    EXPECT_EQ(report.queueMs, 0.5);
    ASSERT_EQ(report.passMs.size(), 2u);
    EXPECT_EQ(report.passMs[1].first, "gather");
    EXPECT_EQ(report.bytes, patch.message->size());
}

TEST(FramePublisher, EachClientGetsTheFrameOrCountsItDropped) {
    const auto rgba = gradient(64, 32);
    auto fast = link(true, 2), full = link(true, 1);
    // `full` still has frame 1 in flight: its window of one is full.
    ASSERT_TRUE(full->offerFrame(1, "{}", std::make_shared<const std::string>("x")));
    const EncodedFrame patch =
        encodeFrame(rgba, 64, 32, TileRect{0, 0, 16, 16}, ImageCodec::Jpeg, 80, false, 2);
    nlohmann::json stats = rendererStats();
    addPublishingStats(stats, patch, "balanced", false, "builtin:cornell", 64, 32);
    FrameReport report;
    const bool missed = offerToClients({fast, full}, stats, patch, false, 1, report);
    EXPECT_EQ(report.delivered, 1u);
    EXPECT_EQ(report.dropped, 1u);
    EXPECT_TRUE(missed) << "a patch one client skipped: the next image must go whole";
    EXPECT_EQ(stats["viewers"], 1);
    EXPECT_EQ(fast->newestOffered(), 2u);
    OutgoingMessage out;
    ASSERT_TRUE(fast->pop(out));
    EXPECT_FALSE(out.binary) << "the stats text first";
    EXPECT_EQ(nlohmann::json::parse(*out.data)["frame"], 2);
    ASSERT_TRUE(fast->pop(out));
    EXPECT_TRUE(out.binary);
    EXPECT_EQ(out.data, patch.message) << "the same bytes, shared";
}

} // namespace
} // namespace gis
