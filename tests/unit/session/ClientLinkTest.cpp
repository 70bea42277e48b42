// Pacing per client: the window of unacknowledged frames, latest-wins replacement and the text cap.
#include <gtest/gtest.h>

#include "session/ClientLink.h"

namespace {

std::shared_ptr<const std::string> bytes(const char* s) {
    return std::make_shared<const std::string>(s);
}

std::vector<std::string> drain(gis::ClientLink& link) {
    std::vector<std::string> out;
    gis::OutgoingMessage m;
    while (link.pop(m)) out.push_back((m.binary ? "bin:" : "txt:") + *m.data);
    return out;
}

} // namespace

TEST(ClientLink, WindowLimitsFramesInFlightAndAckFreesIt) {
    int wakes = 0;
    gis::ClientLink link(gis::ClientRole::Controller, 2, [&] { ++wakes; });
    EXPECT_TRUE(link.offerFrame(1, "s1", bytes("f1")));
    EXPECT_EQ(drain(link), (std::vector<std::string>{"txt:s1", "bin:f1"}));
    EXPECT_TRUE(link.offerFrame(2, "s2", bytes("f2")));
    drain(link);
    EXPECT_TRUE(link.windowFull());
    EXPECT_FALSE(link.offerFrame(3, "s3", bytes("f3"))); // skipped, not queued
    EXPECT_EQ(link.droppedFrames(), 1u);
    EXPECT_FALSE(link.hasOutgoing());
    link.ack(2); // acknowledging the latest frees the older one too
    EXPECT_EQ(link.inFlight(), 0u);
    EXPECT_TRUE(link.offerFrame(4, "s4", bytes("f4")));
    EXPECT_EQ(wakes, 3);
}

TEST(ClientLink, UnsentFrameIsReplacedByANewerOne) {
    gis::ClientLink link(gis::ClientRole::Viewer, 4, nullptr);
    link.pushText("state");
    link.offerFrame(1, "s1", bytes("f1"));
    link.offerFrame(2, "s2", bytes("f2"));
    EXPECT_EQ(drain(link), (std::vector<std::string>{"txt:state", "txt:s2", "bin:f2"}));
    EXPECT_EQ(link.droppedFrames(), 1u);
    EXPECT_EQ(link.inFlight(), 1u); // frame 1 left the window with its replacement
}

TEST(ClientLink, AHalfSentPairIsCompletedNotReplaced) {
    gis::ClientLink link(gis::ClientRole::Controller, 4, nullptr);
    link.offerFrame(1, "s1", bytes("f1"));
    gis::OutgoingMessage m;
    ASSERT_TRUE(link.pop(m)); // stats of frame 1 are on the wire
    link.offerFrame(2, "s2", bytes("f2"));
    EXPECT_EQ(drain(link), (std::vector<std::string>{"bin:f1", "txt:s2", "bin:f2"}));
    EXPECT_EQ(link.droppedFrames(), 0u);
}

TEST(ClientLink, SnapshotsBypassTheWindowAndAreNeverReplaced) {
    gis::ClientLink link(gis::ClientRole::Controller, 1, nullptr);
    link.offerFrame(1, "s1", bytes("f1"));
    EXPECT_TRUE(link.offerFrame(2, "snap", bytes("png"), true));
    link.offerFrame(3, "s3", bytes("f3")); // replaces frame 1 (unsent), keeps the snapshot
    EXPECT_EQ(drain(link), (std::vector<std::string>{"txt:snap", "bin:png", "txt:s3", "bin:f3"}));
}

TEST(ClientLink, TextCapAndCloseDropMessages) {
    gis::ClientLink link(gis::ClientRole::Controller, 1, nullptr, 2);
    EXPECT_TRUE(link.pushText("a"));
    EXPECT_TRUE(link.pushText("b"));
    EXPECT_FALSE(link.pushText("c"));
    EXPECT_EQ(link.droppedText(), 1u);
    link.close();
    EXPECT_TRUE(link.closed());
    EXPECT_FALSE(link.hasOutgoing());
    EXPECT_FALSE(link.offerFrame(1, "s", bytes("f")));
}

TEST(ClientLink, AcksOfFramesNeverOfferedAreRefused) {
    gis::ClientLink link(gis::ClientRole::Controller, 2, [] {});
    EXPECT_FALSE(link.ack(1)) << "nothing was offered yet";
    ASSERT_TRUE(link.offerFrame(1, "s1", std::make_shared<const std::string>("f1")));
    EXPECT_TRUE(link.windowFull() == false);
    EXPECT_FALSE(link.ack(4294967295u));
    EXPECT_EQ(link.inFlight(), 1u) << "a refused ack frees nothing";
    EXPECT_TRUE(link.ack(1));
    EXPECT_EQ(link.inFlight(), 0u);
    EXPECT_EQ(link.newestOffered(), 1u);
}

TEST(ClientLink, PatchesAreNeverReplacedButAWholeFrameReplacesThem) {
    gis::ClientLink link(gis::ClientRole::Controller, 4, nullptr, 64, /*acceptsPatches=*/true);
    EXPECT_TRUE(link.acceptsPatches());
    link.offerFrame(1, "s1", bytes("f1"));              // whole
    link.offerFrame(2, "p2", bytes("g2"), false, true); // a patch over frame 1: both stay
    link.offerFrame(3, "p3", bytes("g3"), false, true); // and over patch 2
    EXPECT_EQ(drain(link),
              (std::vector<std::string>{"txt:s1", "bin:f1", "txt:p2", "bin:g2", "txt:p3", "bin:g3"}));
    EXPECT_EQ(link.droppedFrames(), 0u);
    link.ack(3);
    link.offerFrame(4, "p4", bytes("g4"), false, true);
    link.offerFrame(5, "s5", bytes("f5")); // a whole frame supersedes the unsent patch
    EXPECT_EQ(drain(link), (std::vector<std::string>{"txt:s5", "bin:f5"}));
    EXPECT_EQ(link.droppedFrames(), 1u);
    EXPECT_FALSE(gis::ClientLink(gis::ClientRole::Viewer, 1, nullptr).acceptsPatches());
}
