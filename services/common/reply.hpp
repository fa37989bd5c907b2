#pragma once
// The answer half of a call on the bus. A requester puts a Reply<T> in its request message; whoever handles
// the request calls it once with the result, from any thread, and the requester's completion handler runs on
// the requester's strand with that result.
//
// The bus copies a message to every subscriber, so copies of a Reply share one state: the first answer wins
// and later ones are ignored. When the last copy goes away unanswered (nobody subscribed to the request, or
// the service that took it stopped and dropped it), the handler runs with the fallback given at creation, so
// a requester never waits forever. Either way it runs exactly once.
//
// The handler may capture the requester's `this`: it only runs while the requester's ReplyGuard exists. As
// with a Subscription, destroy the guard on the requester's strand (or once its io_context no longer runs),
// so a completion already posted cannot run concurrently with the requester's destruction. A Reply must not
// outlive the io_context of the requester's strand, which its fallback is posted to.
#include <atomic>
#include <functional>
#include <memory>
#include <utility>

#include "services/common/asio.hpp"

namespace airseg {

/// Held by a requester for as long as its Reply handlers may run; destroying it drops every completion that
/// has not run yet, including ones already posted.
class ReplyGuard {
  public:
    ReplyGuard() = default;
    ReplyGuard(const ReplyGuard&) = delete;
    ReplyGuard& operator=(const ReplyGuard&) = delete;
    ~ReplyGuard() { alive_->store(false); }

  private:
    template <class T>
    friend class Reply;
    std::shared_ptr<std::atomic<bool>> alive_ = std::make_shared<std::atomic<bool>>(true);
};

template <class T>
class Reply {
  public:
    /// An empty Reply: nobody waits for an answer, and answering it does nothing.
    Reply() = default;

    template <class Handler>
    Reply(const Strand& strand, const ReplyGuard& guard, T fallback, Handler&& handler)
        : state_(std::make_shared<State>(strand, guard.alive_, std::move(fallback),
                                         std::function<void(T)>(std::forward<Handler>(handler)))) {}

    /// Whether someone waits for the answer.
    explicit operator bool() const { return state_ != nullptr; }

    /// Completes the call, unless another copy already did.
    void operator()(T result) const {
        if (state_) {
            state_->complete(std::move(result));
        }
    }

  private:
    struct State {
        State(Strand s, std::shared_ptr<std::atomic<bool>> a, T f, std::function<void(T)> h)
            : strand(std::move(s)), alive(std::move(a)), fallback(std::move(f)), handler(std::move(h)) {}
        State(const State&) = delete;
        State& operator=(const State&) = delete;
        // No copy is left to answer: the requester gets the fallback.
        ~State() { complete(std::move(fallback)); }

        void complete(T result) {
            if (answered.exchange(true)) {
                return;
            }
            // Only the winner of the exchange gets here, so the handler is moved out once.
            asio::post(strand,
                       [alive = alive, handler = std::move(handler), result = std::move(result)]() mutable {
                           if (alive->load()) {
                               handler(std::move(result));
                           }
                       });
        }

        Strand strand;
        std::shared_ptr<std::atomic<bool>> alive;
        T fallback;
        std::function<void(T)> handler;
        std::atomic<bool> answered{false};
    };
    std::shared_ptr<State> state_;
};

}  // namespace airseg
