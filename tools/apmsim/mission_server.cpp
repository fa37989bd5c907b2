#include "tools/apmsim/mission_server.hpp"

#include <cmath>

#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::apmsim {

namespace {

namespace mv = mavlink;

constexpr std::uint8_t kOurSystem = 1;
constexpr std::uint8_t kMissionTypeMission = 0;

bool for_us(std::uint8_t target_system) {
    return target_system == kOurSystem || target_system == 0;
}

StoredItem from_float_item(const mv::MissionItem& m) {
    StoredItem s;
    s.command = m.command;
    s.frame = m.frame;
    s.autocontinue = m.autocontinue;
    s.param1 = m.param1;
    s.param2 = m.param2;
    s.param3 = m.param3;
    s.param4 = m.param4;
    // MISSION_ITEM carries degrees as float; the board stores 1e-7 degrees.
    s.lat_e7 =
        std::isfinite(m.x) ? static_cast<std::int32_t>(std::lround(static_cast<double>(m.x) * 1e7)) : 0;
    s.lon_e7 =
        std::isfinite(m.y) ? static_cast<std::int32_t>(std::lround(static_cast<double>(m.y) * 1e7)) : 0;
    s.alt = m.z;
    return s;
}

StoredItem from_int_item(const mv::MissionItemInt& m) {
    StoredItem s;
    s.command = m.command;
    s.frame = m.frame;
    s.autocontinue = m.autocontinue;
    s.param1 = m.param1;
    s.param2 = m.param2;
    s.param3 = m.param3;
    s.param4 = m.param4;
    s.lat_e7 = m.x;
    s.lon_e7 = m.y;
    s.alt = m.z;
    return s;
}

template <class M>
void fill_common(M& m, const StoredItem& s, const mv::Frame& to, std::uint16_t seq, bool current) {
    m.target_system = to.sysid;
    m.target_component = to.compid;
    m.seq = seq;
    m.frame = s.frame;
    m.command = s.command;
    m.current = current ? 1 : 0;
    m.autocontinue = s.autocontinue;
    m.param1 = s.param1;
    m.param2 = s.param2;
    m.param3 = s.param3;
    m.param4 = s.param4;
    m.z = s.alt;
}

}  // namespace

bool MissionServer::handle(const mv::Frame& f, TimePoint now) {
    switch (f.msgid) {
        case mv::MissionRequestList::kId: {
            const auto m = mv::decode_payload<mv::MissionRequestList>(f.payload_view());
            if (!for_us(m.target_system)) {
                return true;
            }
            if (m.mission_type != kMissionTypeMission) {
                ack(f, MissionResult::Unsupported);  // no fence or rally points on this board
                return true;
            }
            on_request_list(f);
            return true;
        }
        case mv::MissionRequest::kId: {
            const auto m = mv::decode_payload<mv::MissionRequest>(f.payload_view());
            if (for_us(m.target_system)) {
                on_request(f, m.seq, false);
            }
            return true;
        }
        case mv::MissionRequestInt::kId: {
            const auto m = mv::decode_payload<mv::MissionRequestInt>(f.payload_view());
            if (for_us(m.target_system)) {
                on_request(f, m.seq, true);
            }
            return true;
        }
        case mv::MissionCount::kId: {
            const auto m = mv::decode_payload<mv::MissionCount>(f.payload_view());
            if (!for_us(m.target_system)) {
                return true;
            }
            if (m.mission_type != kMissionTypeMission) {
                ack(f, MissionResult::Unsupported);
                return true;
            }
            on_count(f, m.count, now);
            return true;
        }
        case mv::MissionWritePartialList::kId: {
            const auto m = mv::decode_payload<mv::MissionWritePartialList>(f.payload_view());
            if (for_us(m.target_system)) {
                on_partial(f, m.start_index, m.end_index, now);
            }
            return true;
        }
        case mv::MissionItem::kId: {
            const auto m = mv::decode_payload<mv::MissionItem>(f.payload_view());
            if (for_us(m.target_system)) {
                on_item(f, m.seq, m.current, from_float_item(m), now);
            }
            return true;
        }
        case mv::MissionItemInt::kId: {
            const auto m = mv::decode_payload<mv::MissionItemInt>(f.payload_view());
            if (for_us(m.target_system)) {
                on_item(f, m.seq, m.current, from_int_item(m), now);
            }
            return true;
        }
        case mv::MissionClearAll::kId: {
            const auto m = mv::decode_payload<mv::MissionClearAll>(f.payload_view());
            if (!for_us(m.target_system)) {
                return true;
            }
            if (m.mission_type != kMissionTypeMission) {
                ack(f, MissionResult::Unsupported);
                return true;
            }
            on_clear(f);
            return true;
        }
        case mv::MissionSetCurrent::kId: {
            const auto m = mv::decode_payload<mv::MissionSetCurrent>(f.payload_view());
            if (for_us(m.target_system)) {
                on_set_current(m.seq);
            }
            return true;
        }
        case mv::MissionAck::kId:
            return true;  // the end of a download; the board keeps no download state
        default:
            return false;
    }
}

void MissionServer::on_request_list(const mv::Frame& f) {
    if (upload_) {
        ++stats_.denied;
        ack(f, MissionResult::Denied);
        return;
    }
    mv::MissionCount c;
    c.target_system = f.sysid;
    c.target_component = f.compid;
    c.count = static_cast<std::uint16_t>(store_.count());
    out_.reply(c);
}

void MissionServer::on_request(const mv::Frame& f, std::uint16_t seq, bool as_int) {
    if (seq >= store_.count()) {
        ack(f, MissionResult::InvalidSequence);
        return;
    }
    const StoredItem item = seq == 0 ? hooks_.home() : store_.at(seq);
    const bool current = seq == hooks_.current();
    ++stats_.items_sent;
    if (as_int) {
        mv::MissionItemInt m;
        fill_common(m, item, f, seq, current);
        m.x = item.lat_e7;
        m.y = item.lon_e7;
        out_.reply(m);
    } else {
        mv::MissionItem m;
        fill_common(m, item, f, seq, current);
        m.x = static_cast<float>(item.lat_e7 / 1e7);
        m.y = static_cast<float>(item.lon_e7 / 1e7);
        out_.reply(m);
    }
}

bool MissionServer::other_uploader(const mv::Frame& f) const {
    return upload_ && (upload_->sysid != f.sysid || upload_->compid != f.compid);
}

void MissionServer::on_count(const mv::Frame& f, std::uint16_t count, TimePoint now) {
    if (other_uploader(f)) {
        ++stats_.denied;
        ack(f, MissionResult::Denied);
        return;
    }
    upload_.reset();  // the same GCS starting again
    if (count > store_.capacity()) {
        ack(f, MissionResult::NoSpace);
        return;
    }
    if (count <= 1) {
        // Nothing to request: the mission is home alone.
        store_.truncate(1);
        ++stats_.uploads_completed;
        ack(f, MissionResult::Accepted);
        hooks_.changed();
        return;
    }
    upload_ = Upload{f.sysid, f.compid, 0, count, false, now, now};
    request_next(now);
}

void MissionServer::on_partial(const mv::Frame& f, std::int16_t start, std::int16_t end, TimePoint now) {
    if (other_uploader(f)) {
        ++stats_.denied;
        ack(f, MissionResult::Denied);
        return;
    }
    const auto count = static_cast<std::int32_t>(store_.count());
    // As APM:Rover 2.x checks it: both ends may reach the current count (appending one item).
    if (start < 0 || end < start || start > count || end > count ||
        static_cast<std::size_t>(end) >= store_.capacity()) {
        mv::Statustext t;
        t.severity = 4;  // MAV_SEVERITY_WARNING
        mv::set_text(t.text, "flight plan update rejected");
        out_.reply(t);
        ack(f, MissionResult::Error);
        return;
    }
    upload_ = Upload{
        f.sysid, f.compid, static_cast<std::uint16_t>(start), static_cast<std::uint16_t>(end + 1), true,
        now,     now};
    request_next(now);
}

void MissionServer::on_item(const mv::Frame& f, std::uint16_t seq, std::uint8_t current,
                            const StoredItem& item, TimePoint now) {
    if (current == 2) {
        // ArduPilot's guided "go to": not a mission item at all.
        ack(f, hooks_.guided_goto(item) ? MissionResult::Accepted : MissionResult::Error);
        return;
    }
    if (!upload_) {
        ack(f, MissionResult::Error);
        return;
    }
    if (other_uploader(f)) {
        ++stats_.denied;
        ack(f, MissionResult::Denied);
        return;
    }
    if (seq != upload_->next) {
        ack(f, MissionResult::InvalidSequence);
        return;
    }
    if (!store_.write(seq, item)) {
        ack(f, MissionResult::NoSpace);
        upload_.reset();
        return;
    }
    ++stats_.items_received;
    upload_->last_heard = now;
    ++upload_->next;
    if (upload_->next < upload_->end) {
        request_next(now);
        return;
    }
    if (!upload_->partial) {
        store_.truncate(upload_->end);
    }
    upload_.reset();
    ++stats_.uploads_completed;
    ack(f, MissionResult::Accepted);
    mv::Statustext t;
    t.severity = 6;  // MAV_SEVERITY_INFO
    mv::set_text(t.text, "flight plan received");
    out_.reply(t);
    hooks_.changed();
}

void MissionServer::on_clear(const mv::Frame& f) {
    if (upload_ || hooks_.running()) {
        ack(f, MissionResult::Error);
        return;
    }
    store_.truncate(1);
    ack(f, MissionResult::Accepted);
    hooks_.changed();
}

void MissionServer::on_set_current(std::uint16_t seq) {
    if (seq >= store_.count() || !hooks_.set_current(seq)) {
        return;  // the board answers an impossible index with silence
    }
    mv::MissionCurrent c;
    c.seq = seq;
    c.total = static_cast<std::uint16_t>(store_.count() - 1);
    out_.reply(c);
}

void MissionServer::request_next(TimePoint now) {
    mv::MissionRequest r;
    r.target_system = upload_->sysid;
    r.target_component = upload_->compid;
    r.seq = upload_->next;
    upload_->last_request = now;
    out_.reply(r);
}

void MissionServer::handle_timeout(TimePoint now) {
    if (!upload_) {
        return;
    }
    if (now - upload_->last_heard >= give_up_) {
        const Upload u = *upload_;
        upload_.reset();
        ++stats_.uploads_cancelled;
        ack(u.sysid, u.compid, MissionResult::OperationCancelled);
        if (u.partial || u.next > 0) {
            hooks_.changed();
        }
        return;
    }
    if (now - upload_->last_request >= rerequest_) {
        ++stats_.rerequests;
        request_next(now);
    }
}

TimePoint MissionServer::poll_timeout() const {
    if (!upload_) {
        return kNever;
    }
    return std::min(upload_->last_request + rerequest_, upload_->last_heard + give_up_);
}

void MissionServer::ack(const mv::Frame& to, MissionResult result) {
    ack(to.sysid, to.compid, result);
}

void MissionServer::ack(std::uint8_t sysid, std::uint8_t compid, MissionResult result) {
    mv::MissionAck a;
    a.target_system = sysid;
    a.target_component = compid;
    a.type = static_cast<std::uint8_t>(result);
    out_.reply(a);
}

}  // namespace airseg::apmsim
