#include "services/flightplan/window_feeder.hpp"

#include <algorithm>

namespace airseg::flightplan {

namespace {

using autopilot::MissionItem;
using autopilot::VehicleState;

/// What an autopilot answer means to the feeder; the one place its results are told apart.
enum class Answer : std::uint8_t {
    Done,
    Retry,    // not confirmed (no answer, busy, not connected, cut short by the link): asked again
    Refused,  // the autopilot said no to the content or cannot hold it: asking again cannot help
};

Answer answer(autopilot::RequestResult result) {
    switch (result) {
        case autopilot::RequestResult::Ok:
            return Answer::Done;
        case autopilot::RequestResult::Refused:
        case autopilot::RequestResult::Invalid:
            return Answer::Refused;
        case autopilot::RequestResult::Timeout:
        case autopilot::RequestResult::Busy:
        case autopilot::RequestResult::NotReady:
        case autopilot::RequestResult::Cancelled:
            return Answer::Retry;
    }
    return Answer::Retry;
}

}  // namespace

std::optional<std::string> FeederConfig::validate() const {
    if (window < 3) {
        return "flightplan.window must be >= 3";
    }
    if (window > 250) {
        return "flightplan.window must be <= 250";
    }
    if (request_timeout <= Duration::zero()) {
        return "flightplan.request_timeout must be > 0";
    }
    if (fault_backoff < Duration::zero()) {
        return "flightplan.fault_backoff must be >= 0";
    }
    if (lost_reached_tolerance + 2 > window) {
        return "flightplan.lost_reached_tolerance must be <= window - 2";
    }
    return std::nullopt;
}

WindowFeeder::WindowFeeder(FeederConfig config)
    : config_(config),
      confirmed_(config.window + 1u + kWrapSlots),
      written_over_stop_(config.window + 1u + kWrapSlots, false),
      sent_(config.window + 1u + kWrapSlots) {}

std::vector<MissionItem> WindowFeeder::slot_items(std::uint16_t slot, const MissionItem& item) const {
    if (slot != wrap_slot()) {
        return {item};
    }
    // [item, JumpTo(2), place]: a board that runs the do-commands after a waypoint once it is reached
    // (APM:Rover 2.42-2.45) runs them only when a place follows them; AP_Mission follows the jump when it
    // gets to it and looks ahead through it, so the leg from W to slot 2 is planned as one corner, not a
    // stop.
    MissionItem jump;
    jump.kind = MissionItem::Kind::JumpTo;
    jump.jump_slot = kFirstRingSlot;
    MissionItem place = item;
    place.kind = MissionItem::Kind::Waypoint;
    place.hold_s.reset();
    return {item, jump, place};
}

MissionItem WindowFeeder::Entry::item() const {
    MissionItem m;
    m.kind = stop ? MissionItem::Kind::Stop : MissionItem::Kind::Waypoint;
    m.lat = wp.position.lat;
    m.lon = wp.position.lon;
    // A waypoint's unset values (no altitude, speed or radius 0) leave the board its own: altitude relative
    // to home, the leg speed and acceptance radius it has configured.
    m.alt = wp.alt.value_or(0.0);
    if (wp.speed > 0.0) {
        m.speed = wp.speed;
    }
    if (wp.arrival_radius > 0.0) {
        m.radius = wp.arrival_radius;
    }
    return m;
}

MissionItem WindowFeeder::Entry::barrier() const {
    MissionItem m = item();
    m.kind = MissionItem::Kind::Stop;
    return m;
}

bool WindowFeeder::confirmed(const Entry& e) const {
    return holds(e.slot, e.item());
}

bool WindowFeeder::drives_to(const Entry& e) const {
    return mission_ok_ && e.slot < confirmed_.size() && confirmed_[e.slot] == e.item();
}

bool WindowFeeder::holds_stop(std::uint16_t slot) const {
    return mission_ok_ && slot < confirmed_.size() && confirmed_[slot] &&
           confirmed_[slot]->kind == MissionItem::Kind::Stop;
}

WindowFeeder::Chain WindowFeeder::chain_from(std::size_t first) const {
    Chain c{first, false};
    for (; c.entries < queue_.size(); ++c.entries) {
        const Entry& e = queue_[c.entries];
        if (!confirmed(e)) {
            // The head's own slot is the set-current's and the starvation guard's business.
            c.broken = c.entries > 0 && !holds(e.slot, queue_[c.entries - 1].barrier());
            return c;
        }
        if (e.stop) {
            ++c.entries;
            return c;
        }
    }
    c.broken = !queue_.empty() && !holds(ring_next(queue_.back().slot), queue_.back().barrier());
    return c;
}

std::size_t WindowFeeder::capacity() const {
    const bool target_outside = need_set_current_ && !repoint_only_;
    return config_.window - 1u - (target_outside ? 1u : 0u);
}

bool WindowFeeder::holds(std::uint16_t slot, const MissionItem& item) const {
    const auto want = slot_items(slot, item);
    if (!mission_ok_ || static_cast<std::size_t>(slot) + want.size() > confirmed_.size()) {
        return false;
    }
    for (std::size_t i = 0; i < want.size(); ++i) {
        if (confirmed_[slot + i] != want[i]) {
            return false;
        }
    }
    return true;
}

void WindowFeeder::emit(FeederEvent::Kind kind, const Waypoint* wp, std::uint32_t generation,
                        std::string path, std::string detail) {
    FeederEvent e;
    e.kind = kind;
    e.generation = generation;
    if (wp != nullptr) {
        e.plan_index = wp->index;
        e.element = wp->element;
    }
    e.element_path = std::move(path);
    e.detail = std::move(detail);
    events_.push_back(std::move(e));
}

// ---- plan inputs ---------------------------------------------------------------------------------------

void WindowFeeder::replace_plan(PlanFeed feed, TimePoint now) {
    stream_ = std::move(feed.stream);
    held_back_.reset();
    plan_name_ = std::move(feed.name);
    ++generation_;
    extensions_ = 0;
    stream_ended_ = false;
    done_ = false;
    reached_ = 0;
    holds_.clear();
    holding_ = false;
    hold_until_.reset();
    hold_wp_.reset();
    cleared_ = false;
    failed_.reset();
    interrupted_.reset();
    interrupted_by_hand_ = false;
    const bool keep_head = mission_ok_ && !queue_.empty() && !queue_[0].stop && !need_set_current_ &&
                           ap_target_ == queue_[0].slot;
    if (keep_head) {
        queue_.resize(1);
        refill(now);
        check_done();
    } else {
        start_fresh(now);
    }
}

void WindowFeeder::restore_plan(PlanFeed feed, std::uint64_t waypoints_reached, TimePoint now) {
    replace_plan(std::move(feed), now);
    reached_ = waypoints_reached;
}

bool WindowFeeder::skip_to(std::uint64_t index, TimePoint now) {
    if (!stream_ || !stream_->seek(index)) {
        return false;
    }
    restart(now);
    return true;
}

bool WindowFeeder::jump_to(std::string_view element_name, TimePoint now) {
    if (!stream_ || !stream_->jump_to(element_name)) {
        return false;
    }
    restart(now);
    return true;
}

void WindowFeeder::restart(TimePoint now) {
    held_back_.reset();    // the stream was moved on
    interrupted_.reset();  // the operator chose where to go on: taken by hand no more
    interrupted_by_hand_ = false;
    holds_.clear();
    holding_ = false;
    hold_until_.reset();
    hold_wp_.reset();
    stream_ended_ = false;
    done_ = false;
    start_fresh(now);
}

// The new head goes where the vehicle cannot get by itself: after the slot following its target T, which
// gets a barrier at T's point (a vehicle that reaches T before the set-current waits there). A vehicle
// parked on a Stop at T goes nowhere by itself: the head follows T at once. A set-current then points the
// vehicle at the head, and until then nothing it reports is the new window's doing.
void WindowFeeder::start_fresh(TimePoint now) {
    std::uint16_t t = 0;  // none known
    if (ap_target_ && *ap_target_ < confirmed_.size()) {
        t = ring_position(*ap_target_);
    } else if (!queue_.empty()) {
        t = queue_[0].slot;
    }
    std::uint16_t first_slot = kFirstRingSlot;
    old_target_.reset();
    if (t >= kFirstRingSlot && mission_ok_) {
        first_slot = holds_stop(t) ? ring_next(t) : ring_next(ring_next(t));
        if (!holds_stop(t)) {
            old_target_ = t;
        }
    }
    left_frontier(now);
    queue_.clear();
    fresh_slot_ = first_slot;
    need_set_current_ = true;
    repoint_only_ = false;
    refill(now);
    announce_head();
    check_done();
}

void WindowFeeder::continue_with(PlanFeed feed, TimePoint now) {
    stream_ = std::move(feed.stream);
    ++extensions_;
    if (!feed.name.empty()) {
        plan_name_ = std::move(feed.name);
    }
    cleared_ = false;
    if (!stream_ended_) {
        return;  // the queue goes on filling from the new stream
    }
    stream_ended_ = false;
    done_ = false;
    std::optional<std::uint16_t> stop_slot;
    if (!queue_.empty() && queue_.back().stop) {
        stop_slot = queue_.back().slot;
        queue_.pop_back();
    }
    if (queue_.empty()) {
        // Parked on the Stop item: the continuation goes into the next slot, then set-current points there.
        if (stop_slot) {
            ap_target_ = *stop_slot;
        }
        start_fresh(now);
        return;
    }
    refill(now);
    check_done();
}

void WindowFeeder::clear_plan() {
    stream_.reset();
    held_back_.reset();
    queue_.clear();
    holds_.clear();
    holding_ = false;
    hold_until_.reset();
    hold_wp_.reset();
    plan_name_.clear();
    done_ = false;
    cleared_ = true;
    ++generation_;
    extensions_ = 0;
}

void WindowFeeder::pause() {
    paused_ = true;
}

void WindowFeeder::resume() {
    paused_ = false;
    fault_ = false;
    interrupted_.reset();
    interrupted_by_hand_ = false;
    // The operator may have taken the vehicle out of AUTO since (MANUAL, a joystick session), which the
    // feeder is not told: resuming asks for the mission again rather than trusting the last confirmed mode.
    mode_ = Mode::Unknown;
}

void WindowFeeder::release_hold(TimePoint now) {
    if (!holding_) {
        return;
    }
    end_hold(now);
    check_done();
}

// ---- window bookkeeping --------------------------------------------------------------------------------

void WindowFeeder::refill(TimePoint now) {
    while (stream_ && !stream_ended_ && queue_.size() < capacity()) {
        auto w = held_back_ ? std::exchange(held_back_, std::nullopt) : stream_->next();
        const std::uint16_t slot = queue_.empty() ? fresh_slot_ : ring_next(queue_.back().slot);
        if (!w) {
            stream_ended_ = true;
            if (auto err = stream_->error()) {
                emit(FeederEvent::Kind::PlanBlocked, nullptr, generation_, {}, *err);
            }
            if (!queue_.empty() && !queue_.back().stop) {
                Entry stop = queue_.back();
                stop.stop = true;
                stop.holds_after.clear();
                stop.slot = slot;
                queue_.push_back(std::move(stop));
            }
            break;
        }
        if (!w->has_position) {
            if (queue_.empty()) {
                // Nothing to hold after: the vehicle holds where it is, now.
                holds_.push_back(*w);
                if (!holding_) {
                    begin_hold(now);
                }
            } else {
                queue_.back().holds_after.push_back(*w);
            }
            continue;
        }
        if (!queue_.empty() && queue_.back().holds_vehicle()) {
            // The hold's barrier stays until the vehicle is there: a starved daemon cannot let it drive on.
            held_back_ = std::move(w);
            break;
        }
        Entry e;
        e.wp = *w;
        e.slot = slot;
        e.generation = generation_;
        e.element_path = stream_->element_path(w->element);
        queue_.push_back(std::move(e));
    }
}

void WindowFeeder::complete_through(std::size_t position, TimePoint now) {
    for (std::size_t i = 0; i <= position && !queue_.empty(); ++i) {
        Entry e = std::move(queue_.front());
        queue_.pop_front();
        if (queue_.empty()) {
            // A hold's waypoint was the window's last: what follows goes where its barrier is.
            fresh_slot_ = ring_next(e.slot);
        }
        emit(FeederEvent::Kind::WaypointReached, &e.wp, e.generation, e.element_path);
        if (e.generation == generation_) {
            ++reached_;
        }
        if (e.wp.last_of_element) {
            emit(FeederEvent::Kind::ElementFinished, &e.wp, e.generation, e.element_path);
        }
        const bool last = i == position;
        if (last && e.wp.action != WaypointAction::Go) {
            holds_.push_back(e.wp);
        }
        for (auto& h : e.holds_after) {
            if (last) {
                holds_.push_back(h);
            } else {
                // Passed without a reached report: the hold cannot be held any more; report it done.
                emit(FeederEvent::Kind::WaypointReached, &h, e.generation, stream_path(h));
                if (e.generation == generation_) {
                    ++reached_;
                }
            }
        }
    }
    if (!holds_.empty() && !holding_) {
        begin_hold(now);
    }
    refill(now);
    announce_head();
    check_starvation();
    if (!frontier_since_ && !starving_ && !queue_.empty() && !queue_[0].stop && !confirmed(queue_[0]) &&
        holds_stop(queue_[0].slot)) {
        // The vehicle drives on from the waypoint just reached into the barrier: it stops at that point and
        // waits for the next write.
        at_frontier(now);
    }
    if (!queue_.empty() && queue_[0].stop) {
        left_frontier(now);  // the plan's end: the vehicle waits for nothing
    }
    check_done();
}

std::string WindowFeeder::stream_path(const Waypoint& wp) const {
    return stream_ ? stream_->element_path(wp.element) : std::string{};
}

void WindowFeeder::announce_head() {
    // Elements are reported strictly one after the other: the head's start waits for any hold to end.
    if (holding_ || queue_.empty() || queue_[0].stop || queue_[0].announced) {
        return;
    }
    queue_[0].announced = true;
    if (queue_[0].wp.first_of_element) {
        emit(FeederEvent::Kind::ElementStarted, &queue_[0].wp, queue_[0].generation, queue_[0].element_path);
    }
}

void WindowFeeder::begin_hold(TimePoint now) {
    const Waypoint wp = holds_.front();
    holding_ = true;
    hold_wp_ = wp;
    if (!wp.has_position) {
        // A hold without a position has no reached report of its own: reaching it is starting it.
        if (wp.first_of_element) {
            emit(FeederEvent::Kind::ElementStarted, &wp, generation_, stream_path(wp));
        }
        emit(FeederEvent::Kind::WaypointReached, &wp, generation_, stream_path(wp));
        ++reached_;
    }
    if (wp.action == WaypointAction::HoldFor) {
        hold_until_ =
            now + std::chrono::duration_cast<Duration>(std::chrono::duration<double>(wp.hold_seconds));
    } else {
        hold_until_.reset();
    }
    emit(FeederEvent::Kind::HoldStarted, &wp, generation_, stream_path(wp));
}

void WindowFeeder::end_hold(TimePoint now) {
    if (!holding_) {
        return;
    }
    const Waypoint wp = *hold_wp_;
    emit(FeederEvent::Kind::HoldEnded, &wp, generation_, stream_path(wp));
    if (!wp.has_position && wp.last_of_element) {
        emit(FeederEvent::Kind::ElementFinished, &wp, generation_, stream_path(wp));
    }
    holding_ = false;
    hold_until_.reset();
    hold_wp_.reset();
    if (!holds_.empty()) {
        holds_.pop_front();
    }
    if (!holds_.empty()) {
        begin_hold(now);
        return;
    }
    if (frontier_since_ && frontier_is_hold_ && !queue_.empty()) {
        // Held at the hold's barrier, and the next waypoint is not on board yet: from now on the vehicle
        // waits for it.
        frontier_since_ = now;
        frontier_is_hold_ = false;
        count_frontier_stop();
    }
    announce_head();
}

void WindowFeeder::check_done() {
    if (done_ || holding_ || !stream_) {
        return;
    }
    if ((queue_.empty() && stream_ended_) || (!queue_.empty() && queue_[0].stop)) {
        done_ = true;
        emit(FeederEvent::Kind::PlanDone, nullptr, generation_);
    }
}

void WindowFeeder::check_starvation() {
    // A head whose first item is on board (the rest of the wrap's write still landing) is driven right.
    if (!mission_ok_ || need_set_current_ || queue_.empty() || starving_ || drives_to(queue_[0]) ||
        holds_stop(queue_[0].slot)) {
        return;
    }
    // The head's slot holds neither the head nor a barrier: what the autopilot takes from it is not the
    // plan's (the ring's invariant keeps this from happening; a board that lost a write could). Hold, write,
    // then point it at the head again; reached reports until then say nothing about the plan.
    starving_ = true;
    need_set_current_ = true;
    repoint_only_ = false;
    ++counters_.starvation_holds;
    emit(FeederEvent::Kind::WindowStarved, &queue_[0].wp, queue_[0].generation, queue_[0].element_path);
}

void WindowFeeder::at_frontier(TimePoint now) {
    if (frontier_since_) {
        return;
    }
    frontier_since_ = now;
    // Once the head is written the board is pointed at it again: a vehicle parked on a Stop does not leave it
    // because its slot changed (ArduPilot restarts only a waypoint leg when its mission changes).
    need_set_current_ = true;
    repoint_only_ = true;
    ap_target_ = queue_[0].slot;
    frontier_is_hold_ = holding_;
    if (!frontier_is_hold_) {
        count_frontier_stop();
    }
}

void WindowFeeder::count_frontier_stop() {
    ++counters_.frontier_stops;
    emit(FeederEvent::Kind::HeldAtFrontier, &queue_[0].wp, queue_[0].generation, queue_[0].element_path,
         "the next waypoint was not on the autopilot in time: the vehicle waits at the last one written");
}

void WindowFeeder::left_frontier(TimePoint now) {
    if (frontier_since_) {
        if (!frontier_is_hold_) {
            counters_.frontier_wait += now - *frontier_since_;
        }
        frontier_since_.reset();
        frontier_is_hold_ = false;
    }
}

// ---- autopilot inputs ----------------------------------------------------------------------------------

void WindowFeeder::on_reached(std::uint16_t slot, TimePoint now) {
    slot = ring_position(slot);
    if (starving_ || queue_.empty()) {
        ++counters_.ignored_reached;  // the autopilot's target was not the plan's
        return;
    }
    // By the ring's invariant every slot the vehicle can reach from its target holds the entry the window
    // put there or a barrier, so a report of an entry's confirmed slot is that entry reached, whether or not
    // a set-current is still due (the vehicle may have driven on into the window by itself).
    const Entry& head = queue_[0];
    if (stop_kind_told_ && stop_ends_mission_ && slot == head.slot && !head.stop && holds_stop(slot) &&
        sent_[slot] == head.item()) {
        // This board runs a Stop as a jump past its mission's end, which it never reports reached: the slot
        // holds the head's entry, from a write whose answer was given up on (the daemon was stopped while
        // the answer waited in its port) or is still to be read. Taken for the barrier, the arrival would
        // be a wait at the frontier, and the vehicle would be pointed at the slot it had reached again.
        confirmed_[slot] = head.item();
    }
    const std::size_t limit = std::min<std::size_t>(queue_.size(), config_.lost_reached_tolerance + 1);
    for (std::size_t p = 0; p < limit; ++p) {
        const Entry& e = queue_[p];
        if (e.stop) {
            break;
        }
        if (e.slot == slot && drives_to(e)) {
            written_over_stop_[ring_next(slot)] = false;  // it moves on to what the slot holds now
            left_frontier(now);
            need_set_current_ = false;
            repoint_only_ = false;
            ap_target_ = ring_next(slot);
            current_mismatches_ = 0;
            complete_through(p, now);
            return;
        }
    }
    if (slot == queue_[0].slot && !confirmed(queue_[0]) && holds_stop(slot)) {
        at_frontier(now);  // arrived at the barrier
        return;
    }
    ++counters_.ignored_reached;
}

void WindowFeeder::on_current(std::uint16_t slot, TimePoint now) {
    if (queue_.empty() || !mission_ok_) {
        return;
    }
    slot = ring_position(slot);
    if (slot >= confirmed_.size()) {
        if (queue_[0].slot == kFirstRingSlot && !queue_[0].stop && confirmed(queue_[0]) && !starving_ &&
            !frontier_since_) {
            // Heading for slot 2, the wrap's jump target: the 2.x command processor runs the do-commands
            // after the place a jump lands on at once, on the way to it (process_non_nav_command() clears the
            // WAIT_COMMAND the jump's own process_next_command() set, commands_process.pde), so a barrier in
            // slot 3 holds the vehicle short of slot 2. Pointed at slot 2 again, it drives there.
            at_frontier(now);
            return;
        }
        // Past the mission's end: a board whose Stop is a jump there ran it, which it does only once the
        // waypoint before the Stop is reached (slot 2 aside, above). The first Stop on the vehicle's way ends
        // the chain: every entry before it was reached, whatever became of their reports. Once known to wait
        // there, the same report says nothing new (the chain has grown since).
        const Chain c = chain_from(0);
        const std::size_t waypoints = c.entries > 0 && queue_[c.entries - 1].stop ? c.entries - 1 : c.entries;
        if (!c.broken && waypoints > 0 && !starving_ && !frontier_since_ &&
            (!need_set_current_ || repoint_only_)) {
            ap_target_.reset();
            complete_through(waypoints - 1, now);
        }
        return;
    }
    if (slot < 1) {
        return;
    }
    if (slot == queue_[0].slot && !confirmed(queue_[0]) && holds_stop(slot) && !starving_) {
        ap_target_ = slot;
        at_frontier(now);
        return;
    }
    if (slot == queue_[0].slot) {
        ap_target_ = slot;
        if (!need_set_current_) {
            current_mismatches_ = 0;
        }
        return;
    }
    if (!starving_ && !queue_[0].stop && slot == ring_next(queue_[0].slot) && drives_to(queue_[0]) &&
        holds(slot, queue_[0].barrier()) && (queue_.size() == 1 || queue_[1].slot != slot)) {
        // Heading for the head's own barrier: the head is behind the vehicle, whatever became of its reached
        // report. With the head the window's last (a hold's point) no later entry's report would tell.
        ap_target_ = slot;
        current_mismatches_ = 0;
        need_set_current_ = false;
        repoint_only_ = false;
        complete_through(0, now);
        return;
    }
    const std::size_t limit = std::min<std::size_t>(queue_.size(), config_.lost_reached_tolerance + 2);
    if (!starving_) {
        for (std::size_t p = 1; p < limit; ++p) {
            if (queue_[p - 1].stop) {
                break;
            }
            if (queue_[p].slot == slot && (drives_to(queue_[p]) || holds(slot, queue_[p - 1].barrier()))) {
                // The autopilot moved past entries whose reached reports were lost (or are still on the way).
                ap_target_ = slot;
                current_mismatches_ = 0;
                need_set_current_ = false;
                repoint_only_ = false;
                // The slot held a barrier until lately. The board reports its target as it changes, in order
                // with its answers to the writes: a report read before the entry's write was confirmed says
                // the board took the slot while it held the barrier, and it is pointed at the slot again to
                // take what the slot holds now. A report read after the confirmation says it took the entry:
                // never pointed back, however late the report is read (pointed back then, a vehicle that had
                // reached the slot and left it drove it again).
                const bool retake = written_over_stop_[slot] && !drives_to(queue_[p]);
                written_over_stop_[slot] = false;
                complete_through(p - 1, now);
                if (retake && !frontier_since_) {
                    need_set_current_ = true;
                    repoint_only_ = true;
                }
                return;
            }
        }
    }
    if (need_set_current_) {
        ap_target_ = slot;
        return;
    }
    // Anything else twice in a row: point the autopilot back at the head.
    if (++current_mismatches_ >= 2) {
        ap_target_ = slot;
        need_set_current_ = true;
        repoint_only_ = false;
        current_mismatches_ = 0;
    }
}

void WindowFeeder::on_item_stored(std::uint16_t slot, const autopilot::MissionItem& item) {
    // A write of several slots (the wrap) lands item by item: the vehicle may reach its first slot, holding
    // the new entry, before the write's answer. Taken for the barrier the slot held, that arrival would be a
    // wait at the frontier and the vehicle would be pointed at the slot again.
    if (!outstanding_ || !mission_ok_) {
        return;
    }
    const auto* wr = std::get_if<autopilot::WriteMissionItems>(&outstanding_->request.op);
    if (wr == nullptr || slot < wr->first_slot || slot >= confirmed_.size()) {
        return;
    }
    const std::size_t i = slot - wr->first_slot;
    if (i < wr->items.size() && wr->items[i] == item) {
        confirmed_[slot] = item;
    }
}

bool WindowFeeder::plan_active() const {
    return (stream_ || !queue_.empty()) && !done_ && !failed_ && !cleared_;
}

void WindowFeeder::interrupt(std::string why, bool wait_for_operator) {
    ++counters_.interruptions;
    interrupted_ = why;
    interrupted_by_hand_ = wait_for_operator;
    last_interruption_ = why;
    const Waypoint* head = queue_.empty() ? nullptr : &queue_[0].wp;
    emit(FeederEvent::Kind::Interrupted, head, generation_,
         queue_.empty() ? std::string{} : queue_[0].element_path, std::move(why));
}

void WindowFeeder::fail_plan(std::string why) {
    failed_ = why;
    interrupted_.reset();
    interrupted_by_hand_ = false;
    emit(FeederEvent::Kind::PlanFailed, nullptr, generation_, {}, std::move(why));
}

void WindowFeeder::on_mode(VehicleState state, autopilot::ModeChangeCause cause, TimePoint now) {
    const Mode before = mode_;
    const bool requested = cause == autopilot::ModeChangeCause::Requested;
    switch (state) {
        case VehicleState::Unknown:
            mode_ = Mode::Unknown;
            return;
        case VehicleState::ConfigureCheck:
            if (before != Mode::Unknown) {
                // A board seen booting (Rover's INITIALISING) keeps its mission in storage and starts it at
                // slot 1 in AUTO: a waypoint of an old turn of the window. The reboot is declared only once
                // its clock has run on (docs/autopilot.md, Reboots), and AUTO asked for meanwhile drove back
                // there. Its window is written again, as after a declared reboot, before AUTO.
                on_autopilot_rebooted(now);
            }
            mode_ = Mode::Unknown;
            return;
        case VehicleState::WaypointNavigation:
            mode_ = Mode::Auto;
            if (interrupted_ && (!interrupted_by_hand_ || requested)) {
                // Back in AUTO: by the feeder after the board's own HOLD, or by an operator's state command.
                interrupted_.reset();
                interrupted_by_hand_ = false;
                const Waypoint* head = queue_.empty() ? nullptr : &queue_[0].wp;
                emit(FeederEvent::Kind::Continued, head, generation_,
                     queue_.empty() ? std::string{} : queue_[0].element_path, last_interruption_);
            }
            return;
        case VehicleState::Parking:
            mode_ = Mode::Hold;
            break;
        case VehicleState::Directed:
        case VehicleState::ManualNavigation:
        case VehicleState::Manual:
            mode_ = Mode::Manual;
            break;
    }
    // Only leaving AUTO while the plan wants AUTO is news.
    if (before != Mode::Auto || !plan_active() || desired_mode() != Mode::Auto || interrupted_) {
        return;
    }
    const bool ours =
        outstanding_ && std::holds_alternative<autopilot::RequestStateChange>(outstanding_->request.op);
    if (requested) {
        if (ours) {
            return;
        }
        if (mode_ == Mode::Hold) {
            paused_ = true;  // an operator's state command to PARKING: the plan waits for resume
            return;
        }
        interrupt("the operator took the vehicle (manual navigation); plan resume continues", true);
        return;
    }
    if (mode_ == Mode::Manual) {  // the RC pilot's switch, or a manual state nobody here asked for
        interrupt("the RC pilot took the vehicle (MANUAL); plan resume continues", true);
        return;
    }
    // The HOLDs a board whose Stop ends its mission (APM:Rover 2.x) makes by itself. On a board that stays in
    // AUTO on a Stop, a HOLD at these moments is a failsafe or a mode switch, said and undone below.
    if (stop_ends_mission_ && mode_ == Mode::Hold) {
        if (old_target_ && need_set_current_ && !repoint_only_) {
            // After a skip or a new plan it holds at the barrier after its old target: the set-current and
            // AUTO that follow take it to the new head.
            return;
        }
        if (frontier_since_) {
            // It holds at the barrier: the head's write, a set-current and AUTO take it on, as for a vehicle
            // parked there in AUTO.
            return;
        }
        if (queue_.size() == 1 && !queue_[0].stop && queue_[0].slot == kFirstRingSlot &&
            confirmed(queue_[0]) && holds_stop(ring_next(kFirstRingSlot))) {
            // The head is the window's last (a hold's point ends it) and the ring's jump lands on it: the
            // board runs the barrier after it as it takes the jump and holds short of it (on_current, slot
            // 2). Its target report may come after this: it is pointed at slot 2 before AUTO, or AUTO ends
            // its mission again at once.
            at_frontier(now);
            return;
        }
    }
    // The board's own HOLD: a failsafe, a mode switch, a DO_JUMP taken its own way, or the end of its
    // mission. Every slot still holds what it held. If the board's target is the head (or the one after it,
    // whose reached report may still be on its way) AUTO is all it needs: the board goes on from its own
    // target (a board that restarts its mission on entering AUTO is set back by the driver). Otherwise it is
    // pointed at the head first; its reached reports still count meanwhile.
    const bool on_window =
        ap_target_ && !queue_.empty() &&
        (*ap_target_ == queue_[0].slot || (queue_.size() > 1 && *ap_target_ == queue_[1].slot));
    if (!on_window) {
        need_set_current_ = true;
        repoint_only_ = true;
        ap_target_.reset();
    }
    interrupt(
        "the autopilot left AUTO for HOLD by itself (end of its mission, a failsafe or a mode switch); "
        "continuing at the next waypoint",
        false);
}

void WindowFeeder::on_autopilot_rebooted(TimePoint now) {
    left_frontier(now);
    mission_ok_ = false;
    std::fill(confirmed_.begin(), confirmed_.end(), std::nullopt);
    std::fill(sent_.begin(), sent_.end(), std::nullopt);
    ap_target_.reset();
    mode_ = Mode::Unknown;
    outstanding_.reset();
    need_set_current_ = true;
    repoint_only_ = false;
    starving_ = false;
    if (!config_.resume_after_reboot && !queue_.empty() && !done_) {
        paused_ = true;
    }
}

void WindowFeeder::on_request_result(std::uint32_t id, autopilot::RequestResult result, TimePoint now,
                                     std::string_view detail) {
    if (!outstanding_ || outstanding_->request.id != id) {
        return;  // stale: retried or reset since
    }
    const FeederRequest request = std::move(outstanding_->request);
    outstanding_.reset();
    const Answer a = answer(result);
    if (a == Answer::Done) {
        consecutive_failures_ = 0;
        request_succeeded(request, now);
        return;
    }
    const bool writes_items = std::holds_alternative<autopilot::UploadMission>(request.op) ||
                              std::holds_alternative<autopilot::WriteMissionItems>(request.op);
    if (a == Answer::Refused && writes_items) {
        // The board does not take these items (the driver has already tried the forms it knows): asking
        // again every fault_backoff would never end. The vehicle is held and the plan ends here.
        consecutive_failures_ = 0;
        fail_plan(detail.empty() ? std::string("the autopilot refused the mission items")
                                 : std::string(detail));
        return;
    }
    if (const auto* change = std::get_if<autopilot::RequestStateChange>(&request.op);
        a == Answer::Refused && change != nullptr && change->state == VehicleState::WaypointNavigation) {
        // The board will not drive the mission (it refused to arm, or refused AUTO) and says why: a plan
        // that cannot start is failed with its reason rather than asked again every fault_backoff.
        consecutive_failures_ = 0;
        fail_plan(detail.empty() ? std::string("the autopilot refused to drive the mission")
                                 : std::string(detail));
        return;
    }
    request_failed(now);
}

void WindowFeeder::request_failed(TimePoint now) {
    // The reconciliation in poll_request() regenerates the same request: retrying needs no copy of it.
    if (++consecutive_failures_ <= config_.retries) {
        ++counters_.retries;
        return;
    }
    consecutive_failures_ = 0;
    ++counters_.failures;
    fault_ = true;
    retry_not_before_ = now + config_.fault_backoff;
    fault_hold_pending_ = true;
    emit(FeederEvent::Kind::RequestFailed, nullptr, generation_, {},
         "autopilot request failed after retries");
}

void WindowFeeder::request_succeeded(const FeederRequest& request, TimePoint now) {
    if (const auto* up = std::get_if<autopilot::UploadMission>(&request.op)) {
        std::fill(confirmed_.begin(), confirmed_.end(), std::nullopt);
        std::fill(written_over_stop_.begin(), written_over_stop_.end(), false);
        std::fill(sent_.begin(), sent_.end(), std::nullopt);
        for (std::size_t i = 0; i < up->items.size() && i + 1 < confirmed_.size(); ++i) {
            confirmed_[i + 1] = up->items[i];
        }
        mission_ok_ = true;
        need_set_current_ = true;
        repoint_only_ = false;
        ap_target_.reset();
    } else if (const auto* wr = std::get_if<autopilot::WriteMissionItems>(&request.op)) {
        for (std::size_t i = 0; i < wr->items.size(); ++i) {
            const std::size_t slot = wr->first_slot + i;
            if (slot < confirmed_.size()) {
                confirmed_[slot] = wr->items[i];
            }
        }
    } else if (const auto* sc = std::get_if<autopilot::SetMissionCurrent>(&request.op)) {
        ap_target_ = sc->slot;
        if (!queue_.empty() && queue_[0].slot == sc->slot) {
            need_set_current_ = false;
            repoint_only_ = false;
            old_target_.reset();
            left_frontier(now);  // pointed at what it waited for (a board held there: AUTO follows)
            refill(now);         // the vehicle is on the window: the slot it left is the window's again
        }
        current_mismatches_ = 0;
    } else if (const auto* change = std::get_if<autopilot::RequestStateChange>(&request.op)) {
        mode_ = change->state == VehicleState::Parking ? Mode::Hold : Mode::Auto;
    }
}

void WindowFeeder::handle_timeout(TimePoint now) {
    if (outstanding_ && now >= outstanding_->deadline) {
        if (now - outstanding_->deadline > kLateWake && !outstanding_->read_grace) {
            outstanding_->read_grace = true;
            // Woken this late, the daemon itself was not running: the answer may be waiting to be read, and
            // asking again now (a set-current above all) would undo what the board did since.
            outstanding_->deadline = now + kReadGrace;
        } else {
            outstanding_.reset();
            request_failed(now);
        }
    }
    if (holding_ && hold_until_ && now >= *hold_until_) {
        end_hold(now);
        check_done();
    }
}

// ---- outputs -------------------------------------------------------------------------------------------

std::optional<WindowFeeder::Mode> WindowFeeder::desired_mode() const {
    if (failed_) {
        return Mode::Hold;
    }
    if (interrupted_by_hand_) {
        return std::nullopt;  // whoever took the vehicle keeps it until resume()
    }
    if (!stream_ && queue_.empty()) {
        return cleared_ ? std::optional<Mode>(Mode::Hold) : std::nullopt;
    }
    if (paused_ || starving_ || fault_ || holding_) {
        return Mode::Hold;
    }
    if (done_ || queue_.empty()) {
        return std::nullopt;  // parked on the Stop item
    }
    return Mode::Auto;
}

bool WindowFeeder::ready_for_auto() const {
    if (!mission_ok_ || need_set_current_ || queue_.empty() || !confirmed(queue_[0])) {
        return false;
    }
    // The head and what follows it on board: the next entry, or the barrier when the head is the last one.
    const Chain c = chain_from(0);
    return !c.broken && c.entries >= std::min<std::size_t>(2, queue_.size());
}

FeederRequest WindowFeeder::issue(decltype(FeederRequest::op) op, TimePoint now) {
    FeederRequest r{next_request_id_++, std::move(op)};
    outstanding_ = Outstanding{r, now + config_.request_timeout};
    return r;
}

std::optional<FeederRequest> WindowFeeder::write(std::uint16_t slot, const MissionItem& item, TimePoint now) {
    // Never rewrite the slot the vehicle is driving to, but for the head (wrong anyway, or the barrier it
    // waits at) or while it is held for a set-current (which makes the autopilot take its target afresh).
    const bool held_for_set_current = mode_ == Mode::Hold && need_set_current_;
    if (ap_target_ == slot && slot != queue_[0].slot && !held_for_set_current) {
        return std::nullopt;
    }
    autopilot::WriteMissionItems w;
    w.first_slot = slot;
    w.items = slot_items(slot, item);
    for (std::size_t i = 0; i < w.items.size() && slot + i < sent_.size(); ++i) {
        sent_[slot + i] = w.items[i];
    }
    return issue(std::move(w), now);
}

// One write at a time, each keeping the invariant: a slot the vehicle can reach gets an entry only once the
// slot after it holds that entry's barrier, and a reachable slot holding anything else gets a barrier first.
// A write is one transfer, so a daemon stopped in the middle of one leaves no half-sealed ring behind.
std::optional<FeederRequest> WindowFeeder::next_write(TimePoint now) {
    if (old_target_ && need_set_current_ && !repoint_only_ && confirmed_[*old_target_] &&
        confirmed_[*old_target_]->kind != MissionItem::Kind::Stop) {
        // Until the set-current, the vehicle may still reach its old target T: the slot after T stops it
        // there.
        MissionItem stop = *confirmed_[*old_target_];
        stop.kind = MissionItem::Kind::Stop;
        stop.hold_s.reset();
        const std::uint16_t after = ring_next(*old_target_);
        if (!holds(after, stop)) {
            return write(after, stop, now);
        }
    }
    const Chain c = chain_from(0);
    if (c.broken) {
        const Entry& good = queue_[c.entries - 1];
        return write(ring_next(good.slot), good.barrier(), now);
    }
    if (c.entries >= queue_.size()) {
        return std::nullopt;
    }
    const Entry& e = queue_[c.entries];
    if (!e.stop) {
        const std::uint16_t after = ring_next(e.slot);
        const bool sealed =
            holds(after, e.barrier()) || (c.entries + 1 < queue_.size() && confirmed(queue_[c.entries + 1]) &&
                                          !chain_from(c.entries + 1).broken);
        if (!sealed) {
            return write(after, e.barrier(), now);
        }
    }
    auto w = write(e.slot, e.item(), now);
    if (w && c.entries > 0 && holds_stop(e.slot)) {
        written_over_stop_[e.slot] = true;
    }
    return w;
}

std::optional<FeederRequest> WindowFeeder::poll_request(TimePoint now) {
    if (outstanding_) {
        return std::nullopt;
    }
    const auto want = desired_mode();
    // Holding is tried at once after a fault, then at the backoff pace like everything else.
    if (want == Mode::Hold && mode_ != Mode::Hold && (now >= retry_not_before_ || fault_hold_pending_)) {
        fault_hold_pending_ = false;
        return issue(autopilot::RequestStateChange{VehicleState::Parking}, now);
    }
    if (queue_.empty() || now < retry_not_before_ || failed_) {
        return std::nullopt;
    }
    if (!mission_ok_) {
        // Every ring position not holding an entry gets the last entry's barrier, the slot after it included.
        // Slot 1 is where a board that restarts its mission on entering AUTO begins before the driver points
        // it on: a place (a 2.x board ends its mission at once on a Stop there).
        const MissionItem filler = queue_.back().barrier();
        std::vector<MissionItem> at(wrap_slot() + 1u, filler);  // by ring position; [0] unused
        for (const auto& e : queue_) {
            at[e.slot] = e.item();
        }
        autopilot::UploadMission up;
        MissionItem start = filler;
        start.kind = MissionItem::Kind::Waypoint;
        up.items.push_back(start);
        for (std::uint16_t s = kFirstRingSlot; s <= wrap_slot(); ++s) {
            for (const auto& m : slot_items(s, at[s])) {
                up.items.push_back(m);
            }
        }
        return issue(std::move(up), now);
    }
    if (need_set_current_ && queue_[0].stop) {
        need_set_current_ = false;  // the plan is at its end: nothing to point the vehicle at
        repoint_only_ = false;
    }
    if (need_set_current_ && confirmed(queue_[0])) {
        const Chain c = chain_from(0);
        if (!c.broken && c.entries >= std::min<std::size_t>(2, queue_.size())) {
            return issue(autopilot::SetMissionCurrent{queue_[0].slot}, now);
        }
    }
    if (auto w = next_write(now)) {
        return w;
    }
    if (ready_for_auto()) {
        starving_ = false;
        if (fault_ && !chain_from(0).broken && chain_from(0).entries == queue_.size()) {
            fault_ = false;
        }
    }
    if (desired_mode() == Mode::Auto && mode_ != Mode::Auto && ready_for_auto()) {
        return issue(autopilot::RequestStateChange{VehicleState::WaypointNavigation}, now);
    }
    return std::nullopt;
}

TimePoint WindowFeeder::poll_timeout() const {
    TimePoint t = kNever;
    if (outstanding_) {
        t = std::min(t, outstanding_->deadline);
    }
    if (holding_ && hold_until_) {
        t = std::min(t, *hold_until_);
    }
    if (fault_ && retry_not_before_ != TimePoint::min()) {
        t = std::min(t, retry_not_before_);
    }
    return t;
}

std::optional<FeederEvent> WindowFeeder::poll_event() {
    if (events_.empty()) {
        return std::nullopt;
    }
    FeederEvent e = std::move(events_.front());
    events_.pop_front();
    return e;
}

FeederProgress WindowFeeder::progress() const {
    FeederProgress p = counters_;
    p.plan_name = plan_name_;
    p.generation = generation_;
    p.extensions = extensions_;
    p.waypoints_reached = reached_;
    if (!stream_ && queue_.empty()) {
        p.state = PlanState::None;
    } else if (done_) {
        p.state = PlanState::Done;
    } else if (failed_) {
        p.state = PlanState::Failed;
        p.failure = *failed_;
    } else if (paused_) {
        p.state = PlanState::Paused;
    } else {
        p.state = interrupted_ ? PlanState::Interrupted : PlanState::Running;
    }
    // The last interruption stays in view while the plan goes on; a finished plan has none left.
    p.interruption = done_ ? std::string{} : last_interruption_;
    p.held_at_frontier = frontier_since_.has_value() && !frontier_is_hold_;
    if (holding_ && hold_wp_) {
        p.held = stream_path(*hold_wp_);
        p.held_until_released = hold_wp_->action == WaypointAction::HoldUntilReleased;
    }
    if (p.held_at_frontier) {
        p.interruption = "waiting at the last waypoint written to the autopilot for the next one";
    }
    const Entry* first_of_plan = nullptr;
    for (const auto& e : queue_) {
        if (e.stop) {
            break;
        }
        if (e.generation != generation_) {
            continue;
        }
        if (first_of_plan == nullptr) {
            first_of_plan = &e;
        }
        if (confirmed(e)) {
            ++p.window;
        }
    }
    if (!queue_.empty() && !queue_[0].stop) {
        p.next_waypoint = queue_[0].wp.index;
        p.element = queue_[0].element_path;
    }
    if (holding_ && hold_wp_) {
        p.element = stream_path(*hold_wp_);
        p.resume_origin = hold_wp_->origin;
        p.resume_index = hold_wp_->index;
    } else if (first_of_plan != nullptr) {
        p.resume_origin = first_of_plan->wp.origin;
        p.resume_index = first_of_plan->wp.index;
    }
    return p;
}

}  // namespace airseg::flightplan
