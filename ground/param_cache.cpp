#include "ground/param_cache.hpp"

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::ground {

namespace mav = airseg::mavlink;

namespace {
/// The frame again with another param_index (a PARAM_VALUE), re-encoded; empty if it cannot be.
std::vector<std::uint8_t> with_index(const mav::Frame& frame, std::uint16_t index) {
    const auto* info = mav::find_message(frame.msgid);
    const auto* field = info != nullptr ? info->find_field("param_index") : nullptr;
    if (field == nullptr) {
        return {};
    }
    auto payload = frame.payload;
    payload[field->offset] = static_cast<std::uint8_t>(index & 0xFF);
    payload[field->offset + 1u] = static_cast<std::uint8_t>(index >> 8);
    mav::FrameHeader header;
    header.version = frame.version;
    header.seq = frame.seq;
    header.sysid = frame.sysid;
    header.compid = frame.compid;
    header.msgid = frame.msgid;
    header.compat_flags = frame.compat_flags;
    std::array<std::uint8_t, mav::kMaxFrameLength> out{};
    const auto size = mav::encode_message(header, *info, std::span(payload).first(info->length), out);
    return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(size)};
}
}  // namespace

void ParamCache::reset() {
    if (held_ != 0 || count_ != 0) {
        ++stats_.resets;
    }
    source_.reset();
    count_ = 0;
    by_index_.clear();
    index_of_.clear();
    outstanding_.clear();
    held_ = 0;
    boot_ms_.clear();
}

void ParamCache::watch_boot_time(const mav::Frame& frame) {
    std::optional<std::uint32_t> boot_ms;
    if (auto a = mav::decode<mav::Attitude>(frame)) {
        boot_ms = a->time_boot_ms;
    } else if (auto p = mav::decode<mav::GlobalPositionInt>(frame)) {
        boot_ms = p->time_boot_ms;
    } else if (auto t = mav::decode<mav::SystemTime>(frame)) {
        boot_ms = t->time_boot_ms;
    }
    if (!boot_ms) {
        return;
    }
    // Per message: the vehicle sends these as Fast messages, each topic's freshest value replacing an unsent
    // one in its place in the queue, so one message's time may come after a later one of another message's,
    // seconds later after an outage; a message's own times never go back but by a reboot.
    // At most three entries: the messages decoded above.
    if (const auto last = boot_ms_.find(frame.msgid);
        last != boot_ms_.end() && *boot_ms + kRebootBackstepMs < last->second) {
        autopilot_rebooted();  // empties the table
    }
    boot_ms_[frame.msgid] = *boot_ms;
}

void ParamCache::autopilot_rebooted() {
    if (emptied_for_reboot_) {
        return;  // the same reboot, told again
    }
    ++stats_.reboots;
    reset();  // its parameters may have changed with the reboot (a new firmware, a parameter file)
    emptied_for_reboot_ = true;
}

void ParamCache::from_vehicle(const mav::Frame& frame, std::span<const std::uint8_t> bytes) {
    if (source_ && (frame.sysid != source_->first || frame.compid != source_->second)) {
        if (frame.msgid == mav::ParamValue::kId) {
            ++stats_.other_source;
        }
        return;
    }
    if (frame.msgid != mav::ParamValue::kId) {
        if (source_) {
            watch_boot_time(frame);
        }
        return;
    }
    const auto value = mav::decode<mav::ParamValue>(frame);
    if (!value) {
        return;
    }
    ++stats_.values;
    if (value->param_count != count_) {
        reset();  // another parameter table: what was kept belongs to the old one
    }
    source_ = {frame.sysid, frame.compid};
    count_ = value->param_count;
    const std::string id(mav::text_of(value->param_id));
    outstanding_.erase(id);
    std::size_t index = value->param_index;
    if (index >= count_) {
        // An echo of a PARAM_SET may come without its index: the one kept for its id, if any.
        const auto known = index_of_.find(id);
        if (known == index_of_.end()) {
            return;
        }
        index = known->second;
        // Kept with its index, so that an answer read by index says which one it is.
        const auto patched = with_index(frame, static_cast<std::uint16_t>(index));
        if (patched.empty()) {
            return;
        }
        return store(id, index, patched);
    }
    store(id, index, bytes);
}

void ParamCache::store(const std::string& id, std::size_t index, std::span<const std::uint8_t> bytes) {
    if (index >= kMaxEntries) {
        ++stats_.overflow;
        return;
    }
    emptied_for_reboot_ = false;
    if (by_index_.size() <= index) {
        by_index_.resize(std::min(count_, kMaxEntries));
    }
    auto& slot = by_index_[index];
    if (!slot) {
        ++held_;
    } else if (slot->id != id) {
        index_of_.erase(slot->id);
    }
    slot = Entry{id, {bytes.begin(), bytes.end()}};
    index_of_[id] = index;
}

bool ParamCache::fresh() const {
    return count_ != 0 && count_ <= kMaxEntries && held_ == count_ && outstanding_.empty();
}

bool ParamCache::addressed_to_source(std::uint8_t system, std::uint8_t component) const {
    return source_ && system == source_->first && (component == 0 || component == source_->second);
}

bool ParamCache::answer(const mav::Frame& frame, std::vector<std::uint8_t>& out) {
    if (frame.msgid == mav::ParamSet::kId) {
        if (auto set = mav::decode<mav::ParamSet>(frame); set && outstanding_.size() < kMaxEntries) {
            outstanding_.insert(std::string(mav::text_of(set->param_id)));
        }
        return false;
    }
    const bool list = frame.msgid == mav::ParamRequestList::kId;
    const bool read = frame.msgid == mav::ParamRequestRead::kId;
    if (!list && !read) {
        return false;
    }
    const auto pass_on = [this] {
        ++stats_.passed_on;
        return false;
    };
    if (list) {
        const auto request = mav::decode<mav::ParamRequestList>(frame);
        if (!request || !fresh() || !addressed_to_source(request->target_system, request->target_component)) {
            return pass_on();
        }
        for (const auto& entry : by_index_) {
            out.insert(out.end(), entry->bytes.begin(), entry->bytes.end());
        }
        ++stats_.answered_lists;
        return true;
    }
    const auto request = mav::decode<mav::ParamRequestRead>(frame);
    if (!request || !fresh() || !addressed_to_source(request->target_system, request->target_component)) {
        return pass_on();
    }
    std::size_t index = 0;
    if (request->param_index < 0) {
        const auto it = index_of_.find(std::string(mav::text_of(request->param_id)));
        if (it == index_of_.end()) {
            return pass_on();  // the autopilot answers an unknown name itself (or not at all)
        }
        index = it->second;
    } else {
        index = static_cast<std::size_t>(request->param_index);
        if (index >= by_index_.size()) {
            return pass_on();
        }
    }
    const auto& bytes = by_index_[index]->bytes;
    out.insert(out.end(), bytes.begin(), bytes.end());
    ++stats_.answered_reads;
    return true;
}

ParamCacheStats ParamCache::stats() const {
    ParamCacheStats s = stats_;
    s.entries = held_;
    s.count = count_;
    return s;
}

}  // namespace airseg::ground
