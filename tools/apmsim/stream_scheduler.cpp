#include "tools/apmsim/stream_scheduler.hpp"

#include <algorithm>

#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

const std::vector<GroupInfo>& stream_groups() {
    static const std::vector<GroupInfo> groups{
        {StreamGroup::RawSensors, "RAW_SENS"}, {StreamGroup::ExtendedStatus, "EXT_STAT"},
        {StreamGroup::RcChannels, "RC_CHAN"},  {StreamGroup::RawController, "RAW_CTRL"},
        {StreamGroup::Position, "POSITION"},   {StreamGroup::Extra1, "EXTRA1"},
        {StreamGroup::Extra2, "EXTRA2"},       {StreamGroup::Extra3, "EXTRA3"},
    };
    return groups;
}

std::vector<std::uint32_t> group_messages(StreamGroup group) {
    switch (group) {
        case StreamGroup::ExtendedStatus:
            return {mv::SysStatus::kId, mv::MissionCurrent::kId, mv::GpsRawInt::kId,
                    mv::NavControllerOutput::kId};
        case StreamGroup::RcChannels:
            return {mv::ServoOutputRaw::kId, mv::RcChannelsRaw::kId, mv::RcChannels::kId};
        case StreamGroup::RawController:
            return {mv::ServoOutputRaw::kId};
        case StreamGroup::Position:
            return {mv::GlobalPositionInt::kId};
        case StreamGroup::Extra1:
            return {mv::Attitude::kId};
        case StreamGroup::Extra2:
            return {mv::VfrHud::kId};
        case StreamGroup::Extra3:
            return {mv::SystemTime::kId, mv::BatteryStatus::kId};
        case StreamGroup::RawSensors:  // raw IMU and pressure: not simulated
        case StreamGroup::All:
            return {};
    }
    return {};
}

void StreamScheduler::set_group_rate(StreamGroup group, double hz, TimePoint now) {
    if (group == StreamGroup::All) {
        for (const auto& g : stream_groups()) {
            set_group_rate(g.group, hz, now);
        }
        return;
    }
    group_rates_[group] = std::clamp(hz, 0.0, kMaxRateHz);
    for (std::uint32_t id : group_messages(group)) {
        // A message in several groups goes at the fastest of their rates.
        double fastest = 0;
        for (const auto& g : stream_groups()) {
            const auto msgs = group_messages(g.group);
            if (std::find(msgs.begin(), msgs.end(), id) != msgs.end()) {
                fastest = std::max(fastest, group_rates_[g.group]);
            }
        }
        Slot& s = slots_[id];
        s.group_interval = fastest > 0 ? std::optional<Duration>(std::chrono::duration_cast<Duration>(
                                             std::chrono::duration<double>(1.0 / fastest)))
                                       : std::nullopt;
        reschedule(id, now);
    }
}

void StreamScheduler::set_message_interval(std::uint32_t msgid, std::optional<Duration> interval,
                                           TimePoint now) {
    Slot& s = slots_[msgid];
    s.override_interval = interval;
    reschedule(msgid, now);
}

std::optional<Duration> StreamScheduler::interval_of(std::uint32_t msgid) const {
    const auto it = slots_.find(msgid);
    if (it == slots_.end()) {
        return std::nullopt;
    }
    const Slot& s = it->second;
    if (s.override_interval) {
        return *s.override_interval > Duration::zero() ? s.override_interval : std::nullopt;
    }
    return s.group_interval;
}

void StreamScheduler::reschedule(std::uint32_t msgid, TimePoint now) {
    Slot& s = slots_[msgid];
    const auto interval = interval_of(msgid);
    if (!interval) {
        s.next = kNever;
    } else if (s.next == kNever || s.next > now + *interval) {
        s.next = now + *interval;
    }
}

std::vector<std::uint32_t> StreamScheduler::take_due(TimePoint now) {
    std::vector<std::uint32_t> due;
    for (auto& [id, s] : slots_) {
        if (s.next == kNever || s.next > now) {
            continue;
        }
        due.push_back(id);
        const auto interval = interval_of(id);
        if (!interval) {
            s.next = kNever;
            continue;
        }
        s.next += *interval;
        if (s.next <= now) {
            s.next = now + *interval;  // fell behind (a long step): do not send a burst to catch up
        }
    }
    return due;
}

TimePoint StreamScheduler::next_due() const {
    TimePoint t = kNever;
    for (const auto& [id, s] : slots_) {
        t = std::min(t, s.next);
    }
    return t;
}

void StreamScheduler::clear() {
    group_rates_.clear();
    slots_.clear();
}

}  // namespace airseg::apmsim
