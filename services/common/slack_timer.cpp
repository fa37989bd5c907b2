#include "services/common/slack_timer.hpp"

namespace airseg {

SlackTimer::SlackTimer(Strand strand, WakeSharing* sharing)
    : strand_(strand), sharing_(sharing), timer_(std::move(strand)) {}

SlackTimer::~SlackTimer() {
    if (sharing_ != nullptr && state_->shared_id != 0) {
        sharing_->remove(state_->shared_id);
    }
}

void SlackTimer::cancel() {
    const bool was_armed = state_->due != kNever;
    disarm();
    if (was_armed) {
        reprogram_reactor(timer_);
    } else {
        timer_.cancel();
    }
}

void SlackTimer::disarm() {
    ++state_->generation;
    state_->due = kNever;
    state_->handler = nullptr;
    if (sharing_ != nullptr && state_->shared_id != 0) {
        sharing_->remove(std::exchange(state_->shared_id, 0));
    }
}

void SlackTimer::start(TimePoint due, Duration slack, std::function<void()> on_due) {
    if (state_->due != kNever) {
        reprogram_reactor(timer_);
    }
    disarm();
    const std::uint64_t generation = state_->generation;
    state_->due = due;
    state_->handler = std::move(on_due);
    const bool share = sharing_ != nullptr && slack > Duration::zero();
    timer_.expires_at(share ? due + slack : due);
    timer_.async_wait(
        [this, state = std::weak_ptr<State>(state_), generation](const boost::system::error_code& ec) {
            const auto s = state.lock();
            if (ec || !s || s->generation != generation) {
                return;
            }
            run(true);
        });
    if (share) {
        // Runs on the thread that woke; the tick itself goes to this timer's strand.
        state_->shared_id =
            sharing_->add(due, [this, strand = strand_, state = std::weak_ptr<State>(state_), generation] {
                asio::post(strand, [this, state, generation] {
                    const auto s = state.lock();
                    if (s && s->generation == generation) {
                        run(false);
                    }
                });
            });
    }
}

void SlackTimer::run(bool own_wake_up) {
    auto handler = std::move(state_->handler);
    disarm();  // a registration WakeSharing ran is already forgotten there
    if (!own_wake_up) {
        reprogram_reactor(timer_);  // the wait for due + slack is dropped
    } else if (sharing_ != nullptr) {
        // This tick woke the daemon: the others already due share the wake-up.
        sharing_->woke(SteadyClock::now());
    }
    handler();
}

}  // namespace airseg
