// Frame publishing, without the session's state or threads: a rendered image becomes what clients
// receive. The region sent (a patch only where every client draws patches), the encoded bytes in the
// binary frame message, the fields of the protocol's `stats` message, and the offer to each client
// with what was delivered and dropped. Session::deliver decides whether a patch may go and keeps what
// a joining viewer needs; the rest is here (tests/unit/session/FramePublisherTest.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "encode/Encoder.h"
#include "frame/Tiles.h"
#include "session/ClientLink.h"

namespace gis {

/// One frame as the server reports it to its observers (metrics).
struct FrameReport {
    std::string quality; ///< interactive, balanced, final, fixed
    bool snapshot = false;
    double frameMs = 0, queueMs = 0, encodeMs = 0;
    std::vector<std::pair<std::string, double>> passMs;
    std::size_t bytes = 0;     ///< per client that got it
    std::size_t delivered = 0; ///< clients the frame was sent to
    std::size_t dropped = 0;   ///< clients that skipped it
};

/// A frame ready to go out.
struct EncodedFrame {
    std::uint32_t id = 0;
    ImageCodec codec = ImageCodec::Jpeg;
    std::optional<TileRect> region;             ///< a patch of the image; whole when empty
    int sentWidth = 0, sentHeight = 0;          ///< the region's size, or the image's
    std::shared_ptr<const std::string> message; ///< header + encoded bytes (protocol's binary frame)
    double encodeMs = 0;
};

/// The patch of `patch` that may be sent: clipped to the image, and only when every one of `targets`
/// draws patches and there are any; empty otherwise (send the image whole).
std::optional<TileRect> patchToSend(const std::optional<TileRect>& patch, int width, int height,
                                    const std::vector<std::shared_ptr<ClientLink>>& targets);

/// Encodes `region` of the RGBA8 image (all of it when empty) with `codec` (lossless for snapshots)
/// as frame `id`. Throws gis::Error when the encoder fails.
EncodedFrame encodeFrame(const std::vector<std::uint8_t>& rgba, int width, int height,
                         const std::optional<TileRect>& region, ImageCodec codec, int quality, bool lossless,
                         std::uint32_t id);

/// Adds the publishing fields of `stats` (protocol/schema/server/stats.json): type, frame, quality,
/// refined, snapshot, encode_ms, bytes, codec, scene and, for a patch, patch and the full size.
void addPublishingStats(nlohmann::json& stats, const EncodedFrame& frame, const std::string& quality,
                        bool snapshot, const std::string& sceneName, int width, int height);

/// Offers the frame to each client, `stats` carrying the viewer count and that client's dropped-frame
/// count (left as the last client's: what a joining viewer is replayed). `report` gets delivered and
/// dropped; returns whether a client missed a patch (it then needs the next image whole).
bool offerToClients(const std::vector<std::shared_ptr<ClientLink>>& targets, nlohmann::json& stats,
                    const EncodedFrame& frame, bool snapshot, std::size_t viewers, FrameReport& report);

/// The report of a published frame, from its stats (frame_ms, queue_ms, passes) and encoding.
FrameReport reportOf(const nlohmann::json& stats, const EncodedFrame& frame, const std::string& quality,
                     bool snapshot);

} // namespace gis
