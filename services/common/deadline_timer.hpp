#pragma once
// One asio steady_timer following the poll_timeout() of sans-IO cores (time.hpp). Cores are asked for their
// next deadline after every input, and it mostly comes back unchanged: re-arming the timer for the same
// instant would cost a timer-queue update (and often a timerfd syscall) per input for nothing, so an
// unchanged deadline keeps the wait already running. kNever means no wake-up at all. Given a WakeSharing, a
// deadline that wakes the daemon lets the periodic work already due run in the same wake-up.
#include <cstdint>
#include <memory>
#include <utility>

#include "base/time.hpp"
#include "services/common/asio.hpp"
#include "services/common/wake_sharing.hpp"

namespace airseg {

/// asio reprograms its timerfd only for a new earliest deadline or when the timerfd fires: a deadline moved
/// later, or cancelled, would still wake the process at its old instant, for nothing. A wait already due
/// makes asio reprogram the timerfd at once, without sleeping (its completion finds nothing to do). Drops the
/// timer's pending wait, as expires_at() does.
template <class Timer>
void reprogram_reactor(Timer& timer) {
    timer.expires_at(TimePoint{});
    timer.async_wait([](const boost::system::error_code&) {});
}

/// A steady timer whose executor type is the strand itself: converting a strand to any_io_executor, as
/// asio::steady_timer does for every wait's completion, allocates.
using StrandTimer = asio::basic_waitable_timer<SteadyClock, asio::wait_traits<SteadyClock>, Strand>;

class DeadlineTimer {
  public:
    /// Handlers run on `strand` (the owner's); `sharing` may be null.
    explicit DeadlineTimer(Strand strand, WakeSharing* sharing = nullptr)
        : timer_(std::move(strand)), sharing_(sharing) {}
    DeadlineTimer(const DeadlineTimer&) = delete;
    DeadlineTimer& operator=(const DeadlineTimer&) = delete;
    // The state goes with the owner: a completion already queued when it is destroyed finds nothing to call.
    ~DeadlineTimer() = default;

    /// Calls `on_due()` once `deadline` has passed; a deadline already past is due on the next run of the
    /// executor. The deadline armed now is the only one that fires: any earlier or later one is dropped.
    /// The deadline already armed keeps its wait and its handler (`on_due` is dropped); kNever cancels.
    /// The deadline is disarmed before `on_due` runs, so `on_due` may arm the next one.
    template <class Handler>
    void arm(TimePoint deadline, Handler&& on_due) {
        if (deadline == state_->armed) {
            return;
        }
        if (deadline == kNever) {
            cancel();
            return;
        }
        if (state_->armed != kNever && deadline > state_->armed) {
            reprogram_reactor(timer_);
        }
        state_->armed = deadline;
        const std::uint64_t generation = ++state_->generation;
        timer_.expires_at(deadline);
        timer_.async_wait(
            [state = std::weak_ptr<State>(state_), generation, sharing = sharing_,
             on_due = std::forward<Handler>(on_due)](const boost::system::error_code& ec) mutable {
                // A completion queued before a re-arm, a cancel or the owner's destruction cannot be taken
                // back by asio; the generation tells it apart from the wait armed now.
                const auto s = state.lock();
                if (ec || !s || s->generation != generation) {
                    return;
                }
                s->armed = kNever;
                if (sharing != nullptr) {
                    sharing->woke(SteadyClock::now());
                }
                on_due();
            });
    }

    /// No wake-up until the next arm(); a completion already queued is dropped.
    void cancel() {
        const bool was_armed = state_->armed != kNever;
        state_->armed = kNever;
        ++state_->generation;
        if (was_armed) {
            reprogram_reactor(timer_);
        } else {
            timer_.cancel();
        }
    }

    /// The deadline the timer waits for, kNever when none.
    TimePoint armed() const { return state_->armed; }

  private:
    struct State {
        TimePoint armed = kNever;
        std::uint64_t generation = 0;
    };

    StrandTimer timer_;
    WakeSharing* sharing_;
    std::shared_ptr<State> state_ = std::make_shared<State>();
};

}  // namespace airseg
