#include "session/FramePublisher.h"

#include <algorithm>

#include "core/Timer.h"
#include "session/ProtocolMessages.h"

namespace gis {

std::optional<TileRect> patchToSend(const std::optional<TileRect>& patch, int width, int height,
                                    const std::vector<std::shared_ptr<ClientLink>>& targets) {
    if (!patch || targets.empty() ||
        !std::all_of(targets.begin(), targets.end(), [](const auto& c) { return c->acceptsPatches(); }))
        return std::nullopt;
    const TileRect clipped = clipToImage(*patch, width, height);
    if (clipped.width <= 0 || clipped.height <= 0) return std::nullopt;
    return clipped;
}

EncodedFrame encodeFrame(const std::vector<std::uint8_t>& rgba, int width, int height,
                         const std::optional<TileRect>& region, ImageCodec codec, int quality, bool lossless,
                         std::uint32_t id) {
    EncodedFrame f;
    f.id = id;
    f.codec = codec;
    f.region = region;
    f.sentWidth = region ? region->width : width;
    f.sentHeight = region ? region->height : height;
    const Stopwatch clock;
    const std::vector<std::uint8_t> cropped =
        region ? cropRgba8(rgba, width, height, *region) : std::vector<std::uint8_t>();
    const std::uint8_t* pixels = region ? cropped.data() : rgba.data();
    const std::vector<std::uint8_t> encoded =
        encodeImage(codec, pixels, f.sentWidth, f.sentHeight, quality, {}, lossless);
    f.encodeMs = clock.elapsedMs();
    const std::vector<std::uint8_t> message = makeFrameMessage(id, f.sentWidth, f.sentHeight, codec, encoded);
    f.message = std::make_shared<const std::string>(message.begin(), message.end());
    return f;
}

void addPublishingStats(nlohmann::json& stats, const EncodedFrame& frame, const std::string& quality,
                        bool snapshot, const std::string& sceneName, int width, int height) {
    stats["type"] = "stats";
    stats["frame"] = frame.id;
    stats["quality"] = quality;
    stats["refined"] = quality == "balanced" || quality == "final";
    stats["snapshot"] = snapshot;
    stats["encode_ms"] = frame.encodeMs;
    stats["bytes"] = frame.message->size();
    stats["codec"] = codecName(frame.codec);
    stats["scene"] = sceneName;
    if (frame.region) {
        const TileRect& r = *frame.region;
        stats["patch"] = {{"x", r.x}, {"y", r.y}, {"width", r.width}, {"height", r.height}};
        stats["size"] = {width, height};
    }
}

bool offerToClients(const std::vector<std::shared_ptr<ClientLink>>& targets, nlohmann::json& stats,
                    const EncodedFrame& frame, bool snapshot, std::size_t viewers, FrameReport& report) {
    bool patchMissed = false;
    for (const auto& client : targets) {
        stats["viewers"] = viewers;
        stats["dropped_frames"] = client->droppedFrames();
        if (client->offerFrame(frame.id, stats.dump(), frame.message, snapshot, frame.region.has_value())) {
            ++report.delivered;
        } else {
            ++report.dropped;
            patchMissed = patchMissed || frame.region.has_value();
        }
    }
    return patchMissed;
}

FrameReport reportOf(const nlohmann::json& stats, const EncodedFrame& frame, const std::string& quality,
                     bool snapshot) {
    FrameReport report;
    report.quality = quality;
    report.snapshot = snapshot;
    report.frameMs = stats.value("frame_ms", 0.0);
    report.queueMs = stats.value("queue_ms", 0.0);
    report.encodeMs = frame.encodeMs;
    report.bytes = frame.message->size();
    if (auto passes = stats.find("passes"); passes != stats.end() && passes->is_array())
        for (const auto& p : *passes) report.passMs.emplace_back(p.value("name", ""), p.value("gpu_ms", 0.0));
    return report;
}

} // namespace gis
