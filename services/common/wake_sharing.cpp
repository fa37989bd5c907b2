#include "services/common/wake_sharing.hpp"

#include <algorithm>
#include <utility>

namespace airseg {

WakeSharing::Id WakeSharing::add(TimePoint due, std::function<void()> run) {
    std::lock_guard lock(mutex_);
    const Id id = next_id_++;
    entries_.push_back(Entry{id, due, std::move(run)});
    update_earliest();
    return id;
}

void WakeSharing::remove(Id id) {
    std::lock_guard lock(mutex_);
    const auto it =
        std::find_if(entries_.begin(), entries_.end(), [id](const Entry& e) { return e.id == id; });
    if (it != entries_.end()) {
        entries_.erase(it);
        update_earliest();
    }
}

void WakeSharing::woke(TimePoint now) {
    if (now.time_since_epoch().count() < earliest_.load(std::memory_order_acquire)) {
        return;
    }
    std::vector<std::function<void()>> due;
    {
        std::lock_guard lock(mutex_);
        for (auto it = entries_.begin(); it != entries_.end();) {
            if (it->due <= now) {
                due.push_back(std::move(it->run));
                it = entries_.erase(it);
            } else {
                ++it;
            }
        }
        update_earliest();
    }
    // Outside the lock: a run may post to a strand whose handler arms (adds) again at once.
    for (auto& run : due) {
        run();
    }
    shared_.fetch_add(due.size(), std::memory_order_relaxed);
}

std::size_t WakeSharing::waiting() const {
    std::lock_guard lock(mutex_);
    return entries_.size();
}

void WakeSharing::update_earliest() {
    TimePoint earliest = kNever;
    for (const auto& e : entries_) {
        earliest = std::min(earliest, e.due);
    }
    earliest_.store(earliest.time_since_epoch().count(), std::memory_order_release);
}

}  // namespace airseg
