#include "services/autopilot/ardupilot/mission_client.hpp"

#include <algorithm>
#include <cmath>

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace mav = airseg::mavlink;

namespace {
const char* mission_result_name(std::uint8_t type) {
    static const char* const kNames[] = {"ACCEPTED",
                                         "ERROR",
                                         "UNSUPPORTED_FRAME",
                                         "UNSUPPORTED",
                                         "NO_SPACE",
                                         "INVALID",
                                         "INVALID_PARAM1",
                                         "INVALID_PARAM2",
                                         "INVALID_PARAM3",
                                         "INVALID_PARAM4",
                                         "INVALID_PARAM5",
                                         "INVALID_PARAM6",
                                         "INVALID_PARAM7",
                                         "INVALID_SEQUENCE",
                                         "DENIED",
                                         "OPERATION_CANCELLED"};
    return type < std::size(kNames) ? kNames[type] : "unknown result";
}

// The float frame of an *_INT frame: MISSION_ITEM carries degrees as floats, and the *_INT frames are
// defined for MISSION_ITEM_INT only (a strict board answers MAV_MISSION_UNSUPPORTED_FRAME).
std::uint8_t float_frame(std::uint8_t frame) {
    switch (frame) {
        case 5:  // MAV_FRAME_GLOBAL_INT
            return 0;
        case 6:  // MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
            return 3;
        case 11:  // MAV_FRAME_GLOBAL_TERRAIN_ALT_INT
            return 10;
        default:
            return frame;
    }
}

bool is_global_frame(std::uint8_t frame) {
    switch (frame) {
        case 0:   // MAV_FRAME_GLOBAL
        case 3:   // MAV_FRAME_GLOBAL_RELATIVE_ALT
        case 5:   // MAV_FRAME_GLOBAL_INT
        case 6:   // MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
        case 10:  // MAV_FRAME_GLOBAL_TERRAIN_ALT
        case 11:  // MAV_FRAME_GLOBAL_TERRAIN_ALT_INT
            return true;
        default:
            return false;
    }
}
}  // namespace

const char* to_string(MissionResult r) {
    switch (r) {
        case MissionResult::Success:
            return "success";
        case MissionResult::Timeout:
            return "timeout";
        case MissionResult::Denied:
            return "denied";
        case MissionResult::NoSpace:
            return "no space";
        case MissionResult::InvalidArgument:
            return "invalid argument";
        case MissionResult::Cancelled:
            return "cancelled";
        case MissionResult::Busy:
            return "busy";
    }
    return "?";
}
std::ostream& operator<<(std::ostream& os, MissionResult r) {
    return os << to_string(r);
}

const char* to_string(MissionOperation op) {
    switch (op) {
        case MissionOperation::Upload:
            return "upload";
        case MissionOperation::Download:
            return "download";
        case MissionOperation::WritePartial:
            return "partial write";
        case MissionOperation::SetCurrent:
            return "set current";
        case MissionOperation::Clear:
            return "clear";
    }
    return "?";
}

mav::MissionItemInt to_int_item(const mav::MissionItem& f) {
    mav::MissionItemInt i;
    i.target_system = f.target_system;
    i.target_component = f.target_component;
    i.seq = f.seq;
    i.frame = f.frame;
    i.command = f.command;
    i.current = f.current;
    i.autocontinue = f.autocontinue;
    i.param1 = f.param1;
    i.param2 = f.param2;
    i.param3 = f.param3;
    i.param4 = f.param4;
    const double scale = is_global_frame(f.frame) ? 1e7 : 1.0;
    i.x = static_cast<std::int32_t>(std::lround(static_cast<double>(f.x) * scale));
    i.y = static_cast<std::int32_t>(std::lround(static_cast<double>(f.y) * scale));
    i.z = f.z;
    i.mission_type = f.mission_type;
    return i;
}

mav::MissionItem to_float_item(const mav::MissionItemInt& i) {
    mav::MissionItem f;
    f.target_system = i.target_system;
    f.target_component = i.target_component;
    f.seq = i.seq;
    f.frame = float_frame(i.frame);
    f.command = i.command;
    f.current = i.current;
    f.autocontinue = i.autocontinue;
    f.param1 = i.param1;
    f.param2 = i.param2;
    f.param3 = i.param3;
    f.param4 = i.param4;
    const double scale = is_global_frame(i.frame) ? 1e-7 : 1.0;
    f.x = static_cast<float>(static_cast<double>(i.x) * scale);
    f.y = static_cast<float>(static_cast<double>(i.y) * scale);
    f.z = i.z;
    f.mission_type = i.mission_type;
    return f;
}

MissionClient::MissionClient(Outbox& outbox, std::uint8_t target_sysid, std::uint8_t target_compid,
                             MissionConfig config)
    : out_(outbox),
      target_sysid_(target_sysid),
      target_compid_(target_compid),
      config_(config),
      // A floor of 100 ms on the variance term keeps a perfectly steady link from getting a razor-thin
      // timeout.
      rtt_(config.initial_timeout, config.min_timeout, config.max_timeout, Duration::zero(), Duration::zero(),
           milliseconds(100)),
      use_int_(config.use_int) {}

void MissionClient::forget_board() {
    use_int_ = config_.use_int;
    int_proven_ = false;
    fallback_reason_.clear();
}

// --- queueing ----------------------------------------------------------------------------------------------

std::uint32_t MissionClient::upload(std::vector<mav::MissionItemInt> items, TimePoint now) {
    WorkItem w;
    w.op = MissionOperation::Upload;
    w.items = std::move(items);
    return enqueue(std::move(w), now);
}

std::uint32_t MissionClient::download(TimePoint now) {
    WorkItem w;
    w.op = MissionOperation::Download;
    return enqueue(std::move(w), now);
}

std::uint32_t MissionClient::write_partial(std::uint16_t first, std::vector<mav::MissionItemInt> items,
                                           TimePoint now) {
    WorkItem w;
    w.op = MissionOperation::WritePartial;
    w.first = first;
    w.items = std::move(items);
    return enqueue(std::move(w), now);
}

std::uint32_t MissionClient::set_current(std::uint16_t seq, TimePoint now) {
    WorkItem w;
    w.op = MissionOperation::SetCurrent;
    w.first = seq;
    return enqueue(std::move(w), now);
}

std::uint32_t MissionClient::clear(TimePoint now) {
    WorkItem w;
    w.op = MissionOperation::Clear;
    return enqueue(std::move(w), now);
}

std::uint32_t MissionClient::enqueue(WorkItem w, TimePoint now) {
    w.id = next_id_++;
    if (w.op == MissionOperation::Upload || w.op == MissionOperation::WritePartial) {
        const std::size_t end = static_cast<std::size_t>(w.first) + w.items.size();
        if (w.items.empty() && w.op == MissionOperation::WritePartial) {
            reject(w.op, w.id, MissionResult::InvalidArgument, "a partial write needs at least one item");
            return w.id;
        }
        if (end > config_.max_items) {
            reject(w.op, w.id, MissionResult::InvalidArgument,
                   "slots up to " + std::to_string(end) + " exceed mission.max_items " +
                       std::to_string(config_.max_items));
            return w.id;
        }
        // The vehicle addresses items by seq: make each item carry its slot and our target.
        for (std::size_t i = 0; i < w.items.size(); ++i) {
            auto& it = w.items[i];
            it.seq = static_cast<std::uint16_t>(w.first + i);
            it.target_system = target_sysid_;
            it.target_component = target_compid_;
            it.mission_type = mav::kMissionTypeMission;
        }
    }
    if (work_.size() >= kMaxQueued) {
        reject(w.op, w.id, MissionResult::Busy, std::to_string(kMaxQueued) + " mission operations queued");
        return w.id;
    }
    work_.push_back(std::move(w));
    if (work_.size() == 1) {
        start_front(now);
    }
    return work_.back().id;
}

void MissionClient::reject(MissionOperation op, std::uint32_t id, MissionResult r, std::string detail) {
    done_.push_back(MissionCompletion{id, op, r, std::move(detail), {}, {}});
}

void MissionClient::cancel_all(const std::string& why) {
    for (auto& w : work_) {
        done_.push_back(MissionCompletion{w.id, w.op, MissionResult::Cancelled, why, {}, {}});
    }
    work_.clear();
}

// --- sending -----------------------------------------------------------------------------------------------

Duration MissionClient::base_timeout() const {
    return rtt_.rto();
}

void MissionClient::start_front(TimePoint now) {
    while (!work_.empty() && work_.front().step == Step::NotStarted) {
        WorkItem& w = work_.front();
        switch (w.op) {
            case MissionOperation::Upload:
            case MissionOperation::WritePartial:
                w.step = Step::WaitRequest;
                w.next_seq = w.first;
                break;
            case MissionOperation::Download:
                w.step = Step::WaitCount;
                break;
            case MissionOperation::SetCurrent:
                w.step = Step::WaitCurrent;
                break;
            case MissionOperation::Clear:
                w.step = Step::WaitAck;
                break;
        }
        w.last_progress = now;
        w.last_heard = now;
        transmit(w, now, false);
    }
}

void MissionClient::send_item(WorkItem& w, std::uint16_t seq, bool as_int) {
    const auto& item = w.items[static_cast<std::size_t>(seq - w.first)];
    if (as_int) {
        w.sent_int = true;
        out_.send(item);
    } else {
        out_.send(to_float_item(item));
    }
}

template <class M>
void MissionClient::send_to_mission(M m) {
    m.target_system = target_sysid_;
    m.target_component = target_compid_;
    m.mission_type = mav::kMissionTypeMission;
    out_.send(m);
}

// Sends what the current step waits an answer for: first transmission, or a retry after a timeout.
void MissionClient::transmit(WorkItem& w, TimePoint now, bool retry) {
    bool item_sent = false;
    switch (w.step) {
        case Step::WaitRequest:
            if (w.any_request) {
                send_item(w, w.next_seq, w.answer_int);
                item_sent = true;
            } else if (w.op == MissionOperation::Upload) {
                mav::MissionCount m;
                m.count = static_cast<std::uint16_t>(w.items.size());
                send_to_mission(m);
            } else {
                mav::MissionWritePartialList m;
                m.start_index = static_cast<std::int16_t>(w.first);
                m.end_index = static_cast<std::int16_t>(w.first + w.items.size() - 1);
                send_to_mission(m);
            }
            break;
        case Step::WaitAck:
            if (w.op == MissionOperation::Clear) {
                mav::MissionClearAll m;
                send_to_mission(m);
            } else if (w.items.empty()) {
                mav::MissionCount m;  // an empty upload is acknowledged right after its count
                send_to_mission(m);
            } else {
                send_item(w, w.next_seq, w.answer_int);
                item_sent = true;
            }
            break;
        case Step::WaitCount: {
            mav::MissionRequestList m;
            send_to_mission(m);
            break;
        }
        case Step::WaitItem:
            if (use_int_) {
                mav::MissionRequestInt m;
                m.seq = w.next_seq;
                send_to_mission(m);
            } else {
                mav::MissionRequest m;
                m.seq = w.next_seq;
                send_to_mission(m);
            }
            break;
        case Step::WaitCurrent: {
            mav::MissionSetCurrent m;
            m.target_system = target_sysid_;
            m.target_component = target_compid_;
            m.seq = w.first;
            out_.send(m);
            break;
        }
        case Step::NotStarted:
            return;
    }
    ++w.sends;
    if (retry) {
        ++stats_.retransmissions;
        stray_items_ += item_sent ? 1 : 0;
        if (rtt_.samples() == 0) {
            backoff_ = std::min(backoff_ * 2, 16u);
        }
    }
    w.retransmitted = retry;
    w.sent_at = now;
    w.deadline = now + current_timeout(w);
    w.read_grace = false;
}

// Until the first RTT sample, Karn's rule: the timeout doubles with each retransmission, otherwise a link
// slower than the initial guess would never yield an unambiguous sample. Once the RTT is known a lost frame
// is taken for what it is on a serial radio, random loss, not congestion: a retry waits one timeout
// (SRTT + 4 RTTVAR already covers the variation), so a lossy link gets many quick attempts. That matters:
// ArduPilot abandons an upload after 8 s without an item, and at a few percent of bytes lost most item
// frames are damaged, so an item needs several attempts inside those 8 s.
Duration MissionClient::current_timeout(const WorkItem&) const {
    const unsigned factor = rtt_.samples() != 0 ? 1u : backoff_;
    return std::min<Duration>(base_timeout() * factor, config_.max_timeout);
}

// The vehicle answered something sent with the current step: take an RTT sample and refresh the budget.
void MissionClient::progress(WorkItem& w, TimePoint now) {
    if (!w.retransmitted && w.sent_at != TimePoint{}) {
        rtt_.sample(now - w.sent_at);
        backoff_ = 1;
    }
    w.attempt = 0;
    w.last_progress = now;
}

// The one exit point of a running work item.
void MissionClient::finish(MissionResult result, std::string detail, TimePoint now) {
    WorkItem w = std::move(work_.front());
    work_.pop_front();
    MissionCompletion c{w.id, w.op, result, std::move(detail), {}, {}};
    if (result == MissionResult::Denied || result == MissionResult::NoSpace) {
        c.refusal = refusal_;
    }
    refusal_.reset();
    if (w.op == MissionOperation::Download && result == MissionResult::Success) {
        c.items = std::move(w.items);
    }
    done_.push_back(std::move(c));
    start_front(now);
}

void MissionClient::handle_timeout(TimePoint now) {
    if (work_.empty() || now < work_.front().deadline) {
        return;
    }
    WorkItem& w = work_.front();
    if (now - w.deadline > kLateWake && !w.read_grace) {
        w.read_grace = true;
        // Woken this late, the daemon itself was not running: the vehicle's answer may be waiting in the
        // port. A resend now (a MISSION_SET_CURRENT above all) would take the vehicle back to a slot it has
        // left.
        w.deadline = now + kReadGrace;
        return;
    }
    const bool uploading = w.op == MissionOperation::Upload || w.op == MissionOperation::WritePartial;
    if (uploading && w.any_request && now - w.last_heard >= config_.vehicle_gives_up &&
        w.restarts < config_.retries) {
        // Not even a repeated request for as long as the vehicle waits before it abandons a transfer: it has
        // abandoned this one, and its OPERATION_CANCELLED was lost. Waiting for an answer to our item would
        // wait forever; start again.
        restart(w, now);
        return;
    }
    // Out of budget only when both the attempts and the time since the last progress are spent: on a fast,
    // lossy link the attempts come quickly, and the vehicle is still there.
    if (w.attempt >= config_.retries && now - w.last_progress >= config_.give_up_after) {
        std::string where;
        switch (w.step) {
            case Step::WaitRequest:
                where = w.any_request ? "waiting for the request after item " + std::to_string(w.next_seq)
                                      : "waiting for the first item request";
                break;
            case Step::WaitAck:
                where = "waiting for MISSION_ACK";
                break;
            case Step::WaitCount:
                where = "waiting for MISSION_COUNT";
                break;
            case Step::WaitItem:
                where = "waiting for item " + std::to_string(w.next_seq) + " of " + std::to_string(w.count);
                break;
            case Step::WaitCurrent:
                where = "waiting for MISSION_CURRENT " + std::to_string(w.first);
                break;
            case Step::NotStarted:
                break;
        }
        finish(MissionResult::Timeout,
               "no answer after " + std::to_string(w.attempt + 1) + " attempts, " + where, now);
        return;
    }
    ++w.attempt;
    transmit(w, now, true);
}

TimePoint MissionClient::poll_timeout() const {
    return work_.empty() ? kNever : work_.front().deadline;
}

std::optional<MissionItemsStored> MissionClient::poll_stored() {
    if (stored_.empty()) {
        return std::nullopt;
    }
    const auto s = stored_.front();
    stored_.pop_front();
    return s;
}

std::optional<MissionCompletion> MissionClient::poll_completion() {
    if (done_.empty()) {
        return std::nullopt;
    }
    auto c = std::move(done_.front());
    done_.pop_front();
    return c;
}

// --- receiving ---------------------------------------------------------------------------------------------

bool MissionClient::handle_frame(const mav::Frame& f, TimePoint now) {
    if (f.sysid != target_sysid_) {
        return false;
    }
    switch (f.msgid) {
        case mav::MissionRequestInt::kId: {
            const auto m = mav::decode_payload<mav::MissionRequestInt>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_request(m.seq, true, now);
            }
            return true;
        }
        case mav::MissionRequest::kId: {
            const auto m = mav::decode_payload<mav::MissionRequest>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_request(m.seq, false, now);
            }
            return true;
        }
        case mav::MissionAck::kId: {
            const auto m = mav::decode_payload<mav::MissionAck>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_ack(m.type, now);
            }
            return true;
        }
        case mav::MissionCount::kId: {
            const auto m = mav::decode_payload<mav::MissionCount>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_count(m.count, now);
            }
            return true;
        }
        case mav::MissionItemInt::kId: {
            const auto m = mav::decode_payload<mav::MissionItemInt>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_item(m, now);
            }
            return true;
        }
        case mav::MissionItem::kId: {
            const auto m = mav::decode_payload<mav::MissionItem>(f.payload_view());
            if (out_.addressed_to_us(m.target_system, m.target_component) &&
                m.mission_type == mav::kMissionTypeMission) {
                on_item(to_int_item(m), now);
            }
            return true;
        }
        case mav::MissionCurrent::kId:
            on_current(mav::decode_payload<mav::MissionCurrent>(f.payload_view()).seq, now);
            return true;
        default:
            return false;
    }
}

void MissionClient::on_request(std::uint16_t seq, bool as_int, TimePoint now) {
    if (work_.empty() || (work_.front().step != Step::WaitRequest && work_.front().step != Step::WaitAck) ||
        (work_.front().op != MissionOperation::Upload &&
         work_.front().op != MissionOperation::WritePartial)) {
        ++stats_.ignored_frames;
        return;
    }
    WorkItem& w = work_.front();
    const std::size_t end = static_cast<std::size_t>(w.first) + w.items.size();
    if (seq < w.first || seq >= end) {
        ++stats_.ignored_frames;
        return;
    }
    w.last_heard = now;
    if (!w.any_request) {
        stray_items_ = 0;  // the vehicle answers in order: whatever was sent before this transfer is answered
    }
    const bool fresh = !w.any_request || seq > w.highest_sent;
    if (fresh && w.any_request && w.answer_int) {
        int_proven_ = true;  // it went on after our MISSION_ITEM_INT: it takes them
    }
    if (fresh) {
        if (w.op == MissionOperation::WritePartial && seq > w.first) {
            // The board asks for this item once it holds the one before it (ArduPilot stores each item of a
            // partial write as it comes): those are on board already, before the transfer's MISSION_ACK.
            stored_.push_back({w.id, w.first, seq});
        }
        w.int_repeats = 0;
        progress(w, now);
        if (!w.best || seq > *w.best) {
            // Further than any attempt got: the vehicle's cancels so far did not stop the transfer, so the
            // budget of restarts is refreshed. It is bounded all the same (the best can only grow n times).
            w.best = seq;
            w.restarts = 0;
        }
    } else {
        ++stats_.duplicate_requests;
    }
    w.any_request = true;
    w.highest_sent = std::max(w.highest_sent, seq);
    w.next_seq = seq;
    if (!fresh && w.answer_int && !as_int && !int_proven_ && ++w.int_repeats >= kIntRepeatsBeforeFallback) {
        // Asked again and again for an item answered as MISSION_ITEM_INT, by a board that never took one:
        // it does not know the message (MAVLink-1-era firmware drops it unread).
        ++stats_.float_fallbacks;
        use_int_ = false;
        fallback_reason_ = "item requests repeated after MISSION_ITEM_INT answers";
    }
    // With use_int the item goes as MISSION_ITEM_INT even to a MISSION_REQUEST: float degrees would cost
    // decimetres of position (ArduPilot accepts either form). Without it, the form asked for.
    w.answer_int = as_int || use_int_;
    w.step = (seq + 1u == end) ? Step::WaitAck : Step::WaitRequest;
    // Answer every request, a repeated one too: the vehicle asks again when our item was lost.
    send_item(w, seq, w.answer_int);
    w.retransmitted = !fresh;
    w.sent_at = now;
    if (!fresh) {
        ++stats_.retransmissions;
        ++stray_items_;
    }
    w.deadline = now + current_timeout(w);
    w.read_grace = false;
}

void MissionClient::on_ack(std::uint8_t type, TimePoint now) {
    const bool may_answer_stray_item =
        stray_items_ > 0 && (type == mav::kMissionError || type == mav::kMissionInvalidSequence);
    if (may_answer_stray_item) {
        --stray_items_;
    }
    if (work_.empty()) {
        ++stats_.ignored_frames;
        return;
    }
    WorkItem& w = work_.front();
    const bool uploading = w.op == MissionOperation::Upload || w.op == MissionOperation::WritePartial;
    if (!(uploading || w.op == MissionOperation::Clear) ||
        (w.step != Step::WaitRequest && w.step != Step::WaitAck)) {
        ++stats_.ignored_frames;
        return;
    }
    if (type == mav::kMissionAccepted) {
        if (w.step == Step::WaitAck) {
            progress(w, now);
            finish(MissionResult::Success, {}, now);
        } else {
            ++stats_
                  .ignored_frames;  // an acceptance before the last item: left over from an earlier transfer
        }
        return;
    }
    if (type == mav::kMissionInvalidSequence && uploading) {
        ++stats_.invalid_sequence_acks;
        return;
    }
    if (type == mav::kMissionError && may_answer_stray_item && !(uploading && w.any_request)) {
        // An item we repeated reached the vehicle after it had finished that transfer (ArduPilot answers an
        // item it is not receiving with ERROR). Before this operation's first answer, it is the old
        // transfer's. Were it the vehicle's verdict on this operation, the repeat of the request would get
        // the verdict again, with no stray item left to blame.
        ++stats_.stray_errors;
        return;
    }
    // The vehicle gave up waiting (ArduPilot: 8 s without an item on a bad link, OPERATION_CANCELLED), or it
    // is no longer receiving when one of our items arrives (ERROR: its cancel, or its final acceptance, was
    // lost). Either way the mission on board is not known to be ours: start the transfer again. An error
    // before any item was asked for is the vehicle's verdict on the request itself and is final.
    if (type == mav::kMissionError && !w.any_request && w.restarts > 0) {
        ++stats_.ignored_frames;  // the answer to an item of the abandoned attempt, still on the link
        return;
    }
    if (type == mav::kMissionError && !w.any_request && uploading) {
        // A verdict on the request comes again when the request is repeated (on the next timeout); an
        // answer to an earlier transfer's item does not, and the request's own answer follows it.
        const bool repeated_verdict = w.error_at_send.has_value() && *w.error_at_send != w.sends;
        if (!repeated_verdict) {
            w.error_at_send = w.sends;
            ++stats_.unconfirmed_errors;
            return;
        }
    }
    const bool vehicle_lost_track =
        type == mav::kMissionOperationCancelled || (type == mav::kMissionError && w.any_request);
    if (uploading && vehicle_lost_track && w.restarts < config_.retries) {
        restart(w, now);
        return;
    }
    const std::string answer = std::string("MAV_MISSION_") + mission_result_name(type);
    if (uploading && w.sent_int && type != mav::kMissionNoSpace && use_int_) {
        fall_back_to_float(w, answer, now);
        return;
    }
    const std::string form = !uploading   ? std::string()
                             : w.sent_int ? " to MISSION_ITEM_INT"
                                          : " to MISSION_ITEM";
    refusal_ = type;
    const std::string after = uploading && !w.sent_int && !fallback_reason_.empty()
                                  ? " (MISSION_ITEM_INT was refused before: " + fallback_reason_ + ")"
                                  : "";
    finish(type == mav::kMissionNoSpace ? MissionResult::NoSpace : MissionResult::Denied,
           "autopilot answered " + answer + form + after, now);
}

// The board refused items sent as MISSION_ITEM_INT: it gets MISSION_ITEM (float frames) from now on, and
// the transfer starts again. Once only: a refusal of the float form ends the operation.
void MissionClient::fall_back_to_float(WorkItem& w, const std::string& answer, TimePoint now) {
    ++stats_.float_fallbacks;
    use_int_ = false;
    fallback_reason_ = answer + " to MISSION_ITEM_INT";
    restart(w, now);
}

// The vehicle no longer receives this upload: announce it again from the first item.
void MissionClient::restart(WorkItem& w, TimePoint now) {
    ++w.restarts;
    ++stats_.restarts;
    w.any_request = false;
    w.sent_int = false;
    w.int_repeats = 0;
    w.highest_sent = 0;
    w.next_seq = w.first;
    w.step = Step::WaitRequest;
    w.last_heard = now;
    w.attempt = 0;  // a new transfer, with the retry budget of one (restarts have their own)
    w.last_progress = now;
    transmit(w, now, true);
}

void MissionClient::on_count(std::uint16_t count, TimePoint now) {
    if (work_.empty() || work_.front().op != MissionOperation::Download) {
        ++stats_.ignored_frames;
        return;
    }
    WorkItem& w = work_.front();
    if (w.step != Step::WaitCount) {
        ++stats_.ignored_frames;  // the answer to a repeated REQUEST_LIST
        return;
    }
    progress(w, now);
    if (count > config_.max_items) {
        finish(MissionResult::Denied,
               "autopilot announced " + std::to_string(count) + " items, more than mission.max_items", now);
        return;
    }
    w.count = count;
    w.items.clear();
    w.items.reserve(count);
    w.next_seq = 0;
    if (count == 0) {
        finish_download(now);
        return;
    }
    w.step = Step::WaitItem;
    transmit(w, now, false);
}

// The whole list is in: acknowledge it, as the protocol's downloader ends a transfer.
void MissionClient::finish_download(TimePoint now) {
    mav::MissionAck ack;
    ack.target_system = target_sysid_;
    ack.target_component = target_compid_;
    ack.type = mav::kMissionAccepted;
    out_.send(ack);
    finish(MissionResult::Success, {}, now);
}

void MissionClient::on_item(const mav::MissionItemInt& item, TimePoint now) {
    if (work_.empty() || work_.front().step != Step::WaitItem) {
        ++stats_.ignored_frames;
        return;
    }
    WorkItem& w = work_.front();
    if (item.seq != w.next_seq) {
        ++stats_.ignored_frames;  // a late answer to an earlier request
        return;
    }
    progress(w, now);
    w.items.push_back(item);
    ++w.next_seq;
    if (w.next_seq == w.count) {
        finish_download(now);
        return;
    }
    transmit(w, now, false);
}

void MissionClient::on_current(std::uint16_t seq, TimePoint now) {
    if (work_.empty() || work_.front().step != Step::WaitCurrent) {
        return;  // MISSION_CURRENT is also streamed: not an error
    }
    WorkItem& w = work_.front();
    if (seq == w.first) {
        progress(w, now);
        finish(MissionResult::Success, {}, now);
    }
}

}  // namespace airseg::autopilot::ardupilot
