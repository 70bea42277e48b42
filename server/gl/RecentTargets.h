// Screen-sized targets kept for the shapes their owner rendered at before. The live view moves
// between a few sizes (the frame budget's ladder of scales, refinement tiles, the answer to input
// after a refined image), and each new size allocated and cleared every target again: on llvmpipe
// a frame whose size changed cost 1-4 ms more than one of the same size with the renderer's own
// targets, 6-8 ms with multires_gather's eye hierarchy, at 282 x 240 (docs/interactive.md, "Sizes
// used again"). A shape used again takes its targets back instead. GL-free: the targets are any
// movable type, and what they hold is whatever the owner last wrote (owners overwrite what they
// read, or clear it themselves).
#pragma once

#include <algorithm>
#include <cstddef>
#include <deque>
#include <optional>
#include <utility>

namespace gis::gl {

template <class Key, class Targets> class RecentTargets {
public:
    /// Keeps at most `maxKept` shapes whose costs (pixels, say) add up to at most `maxKeptCost`.
    RecentTargets(std::size_t maxKept, double maxKeptCost) : mMaxKept(maxKept), mMaxKeptCost(maxKeptCost) {}

    /// The targets kept for `key`, which are no longer kept; nothing if there are none.
    std::optional<Targets> take(const Key& key) {
        const auto it =
            std::find_if(mEntries.begin(), mEntries.end(), [&](const Entry& e) { return e.key == key; });
        if (it == mEntries.end()) return std::nullopt;
        std::optional<Targets> out(std::move(it->targets));
        mEntries.erase(it);
        return out;
    }

    /// Keeps `targets` of `key`, costing `cost`, as the most recent; the oldest go (and free their
    /// objects) beyond the limits, and targets that alone cost more than the limit are not kept.
    void keep(const Key& key, Targets targets, double cost) {
        take(key); // one entry per shape
        if (mMaxKept == 0 || !(cost <= mMaxKeptCost)) return;
        mEntries.push_front({key, std::move(targets), cost});
        trim();
    }

    /// A change of shape: the targets of `next`, those kept for it or else `create()`, while the
    /// owner's `current` targets (of `previous`, costing `cost`; none when `previous` is empty) are
    /// kept in their place.
    template <class Create>
    Targets exchange(const Key& next, const std::optional<Key>& previous, Targets current, double cost,
                     Create&& create) {
        std::optional<Targets> kept = take(next);
        if (previous) keep(*previous, std::move(current), cost);
        return kept ? std::move(*kept) : create();
    }

    /// Whether targets of `key` are kept.
    bool holds(const Key& key) const {
        return std::any_of(mEntries.begin(), mEntries.end(), [&](const Entry& e) { return e.key == key; });
    }
    /// A new limit on the kept targets' total cost; those past it go now, the oldest first.
    void setMaxKeptCost(double maxKeptCost) {
        mMaxKeptCost = maxKeptCost;
        trim();
    }

    std::size_t size() const { return mEntries.size(); }
    void clear() { mEntries.clear(); }

private:
    void trim() {
        double total = 0.0;
        std::size_t count = 0;
        for (auto it = mEntries.begin(); it != mEntries.end(); ++it) {
            total += it->cost;
            if (++count > mMaxKept || total > mMaxKeptCost) {
                mEntries.erase(it, mEntries.end());
                break;
            }
        }
    }

    struct Entry {
        Key key;
        Targets targets;
        double cost = 0.0;
    };
    std::size_t mMaxKept;
    double mMaxKeptCost;
    std::deque<Entry> mEntries; ///< most recent first
};

} // namespace gis::gl
