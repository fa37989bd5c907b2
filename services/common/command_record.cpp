#include "services/common/command_record.hpp"

#include <algorithm>

namespace airseg {

CommandRecord::CommandRecord(std::size_t entries, Duration keep)
    : max_entries_(std::max<std::size_t>(1, entries)), keep_(keep) {}

CommandRecord::Id CommandRecord::id_of(const Json& request) {
    const auto it = request.find("request_id");
    if (it == request.end()) {
        return {};
    }
    if (it->is_number_unsigned() || (it->is_number_integer() && it->get<std::int64_t>() >= 0)) {
        return {std::to_string(it->get<std::uint64_t>()), {}};
    }
    if (it->is_string()) {
        const auto& text = it->get_ref<const std::string&>();
        const bool printable =
            std::all_of(text.begin(), text.end(), [](char c) { return c > ' ' && c < 0x7f; });
        if (!text.empty() && text.size() <= kMaxIdLength && printable) {
            return {text, {}};
        }
    }
    return {std::nullopt,
            "\"request_id\" must be a string of 1 to 64 printable ASCII characters without spaces, or an "
            "unsigned integer"};
}

void CommandRecord::forget_old(TimePoint now) {
    // Oldest first; an entry still running stays (its waiting requests need its answer), and so does
    // everything behind it until it is done.
    while (!order_.empty()) {
        auto it = entries_.find(order_.front());
        if (it != entries_.end() && (!it->second.result || now - it->second.at < keep_)) {
            break;
        }
        if (it != entries_.end()) {
            entries_.erase(it);
        }
        order_.pop_front();
    }
}

CommandRecord::Admit CommandRecord::admit(const std::string& id, std::uint64_t fingerprint, TimePoint now,
                                          const Reply& reply) {
    std::unique_lock lock(mutex_);
    forget_old(now);
    if (auto it = entries_.find(id); it != entries_.end()) {
        Entry& e = it->second;
        if (e.fingerprint != fingerprint) {
            ++stats_.conflicts;
            return Admit::Conflict;
        }
        if (!e.result) {
            ++stats_.joined;
            e.waiting.push_back(reply);
            return Admit::Joined;
        }
        ++stats_.replayed;
        CommandResult answer = *e.result;
        answer.replayed = true;
        lock.unlock();
        reply(std::move(answer));
        return Admit::Replayed;
    }
    if (entries_.size() >= max_entries_) {
        // Full before its age: the oldest answered entry goes, counted.
        auto victim = std::find_if(order_.begin(), order_.end(), [&](const std::string& candidate) {
            const auto found = entries_.find(candidate);
            return found == entries_.end() || found->second.result.has_value();
        });
        if (victim == order_.end()) {
            ++stats_.unrecorded;  // every entry is a command still running: this one runs unrecorded
            return Admit::Run;
        }
        entries_.erase(*victim);
        order_.erase(victim);
        ++stats_.forgotten_early;
    }
    entries_.emplace(id, Entry{fingerprint, now, std::nullopt, {}});
    order_.push_back(id);
    ++stats_.recorded;
    return Admit::Run;
}

void CommandRecord::finish(const std::string& id, std::uint64_t fingerprint, const CommandResult& result,
                           TimePoint now) {
    std::vector<Reply> waiting;
    {
        std::lock_guard lock(mutex_);
        auto it = entries_.find(id);
        if (it == entries_.end() || it->second.fingerprint != fingerprint || it->second.result) {
            return;  // run unrecorded
        }
        it->second.result = result;
        it->second.at = now;  // kept for its age from the answer, the moment a client starts to wait for it
        waiting.swap(it->second.waiting);
    }
    for (auto& reply : waiting) {
        CommandResult answer = result;
        answer.replayed = true;
        reply(std::move(answer));
    }
}

CommandRecordStats CommandRecord::stats() const {
    std::lock_guard lock(mutex_);
    CommandRecordStats s = stats_;
    s.entries = entries_.size();
    return s;
}

}  // namespace airseg
