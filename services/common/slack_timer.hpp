#pragma once
// A timer for periodic work that may run up to `slack` after its due time, so that it shares a wake-up the
// daemon has anyway (wake_sharing.hpp). It runs at the first input after `due`, or at `due + slack` when none
// came; with no WakeSharing, or a zero slack, it runs at `due` as a plain timer does.
//
// Arming follows DeadlineTimer: the deadline armed now is the only one that runs, an unchanged deadline
// keeps the wait already running (and its handler), kNever cancels, and the handler may arm the next one.
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>

#include "base/time.hpp"
#include "services/common/asio.hpp"
#include "services/common/deadline_timer.hpp"
#include "services/common/wake_sharing.hpp"

namespace airseg {

class SlackTimer {
  public:
    /// Handlers run on `strand` (the owner's); `sharing` may be null (no sharing: plain timer).
    SlackTimer(Strand strand, WakeSharing* sharing);
    SlackTimer(const SlackTimer&) = delete;
    SlackTimer& operator=(const SlackTimer&) = delete;
    ~SlackTimer();

    template <class Handler>
    void arm(TimePoint due, Duration slack, Handler&& on_due) {
        if (due == state_->due && state_->handler) {
            return;
        }
        if (due == kNever) {
            cancel();
            return;
        }
        start(due, slack, std::function<void()>(std::forward<Handler>(on_due)));
    }

    /// No run until the next arm(); a completion already queued is dropped.
    void cancel();

    /// The due time armed, kNever when none.
    [[nodiscard]] TimePoint due() const { return state_->due; }

  private:
    // Lives as long as the timer; completions hold it weakly, so one queued after the timer's destruction
    // finds nothing, and the generation tells a stale completion from the wait armed now.
    struct State {
        std::uint64_t generation = 0;
        TimePoint due = kNever;
        std::function<void()> handler;
        WakeSharing::Id shared_id = 0;
    };
    void start(TimePoint due, Duration slack, std::function<void()> on_due);
    void run(bool own_wake_up);
    void disarm();

    Strand strand_;
    WakeSharing* sharing_;
    StrandTimer timer_;
    std::shared_ptr<State> state_ = std::make_shared<State>();
};

}  // namespace airseg
