#pragma once
// A small typed in-process bus. Messages are plain C++ types; a subscriber names the type it wants and the
// strand it lives on, and every delivery is posted to that strand, so a service's state is only ever touched
// from its own strand and needs no locks.
//
// Two delivery kinds, after the MAREA primitives:
//  - events  (publish):          every message is delivered to every subscriber, in publish order per
//  publisher.
//  - variables (publish_latest): the latest value wins; a subscriber that has not yet run its previous
//  delivery
//    sees only the newest value. The last value is also kept for late subscribers and for latest<T>().
// Calls (request -> result) are events that carry a Reply<T> (see reply.hpp): the message is copied to each
// subscriber, the first copy answered completes the call on the requester's strand, and a call nobody answers
// completes with the requester's fallback, so a request needs no id and no subscription to its result.
#include <any>
#include <atomic>
#include <concepts>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <typeindex>
#include <vector>

#include "services/common/asio.hpp"

namespace airseg {

class Bus;

/// Keeps a subscription alive; destroying it (or calling reset()) stops further deliveries, including ones
/// already posted but not yet run.
class Subscription {
  public:
    Subscription() = default;
    Subscription(Subscription&&) noexcept = default;
    Subscription& operator=(Subscription&& other) noexcept {
        reset();
        token_ = std::move(other.token_);
        return *this;
    }
    Subscription(const Subscription&) = delete;
    Subscription& operator=(const Subscription&) = delete;
    ~Subscription() { reset(); }

    void reset() {
        if (token_) {
            token_->store(false);
            token_.reset();
        }
    }
    bool active() const { return token_ && token_->load(); }

  private:
    friend class Bus;
    explicit Subscription(std::shared_ptr<std::atomic<bool>> token) : token_(std::move(token)) {}
    std::shared_ptr<std::atomic<bool>> token_;
};

class Bus {
  public:
    Bus() = default;
    Bus(const Bus&) = delete;
    Bus& operator=(const Bus&) = delete;

    template <class Msg, class Handler>
    [[nodiscard]] Subscription subscribe(const Strand& strand, Handler&& handler) {
        auto sub = std::make_shared<Subscriber<Msg>>(
            strand, std::function<void(const Msg&)>(std::forward<Handler>(handler)));
        std::shared_ptr<const Msg> retained;
        {
            std::lock_guard lock(mutex_);
            auto& topic = topics_[std::type_index(typeid(Msg))];
            prune(topic);
            topic.subscribers.push_back(sub);
            if (topic.latest.has_value()) {
                retained = std::any_cast<std::shared_ptr<const Msg>>(topic.latest);
            }
        }
        // A late subscriber to a variable starts from its current value.
        if (retained) {
            deliver_latest(sub, std::move(retained));
        }
        return Subscription(sub->alive);
    }

    /// Event: every subscriber gets every message.
    template <class Msg>
    void publish(Msg msg) {
        auto shared = std::make_shared<const Msg>(std::move(msg));
        for (auto& sub : subscribers_of<Msg>()) {
            asio::post(sub->strand, [sub, shared] {
                if (sub->alive->load()) {
                    sub->handler(*shared);
                }
            });
        }
    }

    /// Variable: the newest value replaces an undelivered older one; the value is retained. A value equal to
    /// the retained one (for a type that can be compared) changes nothing and is not delivered again: a
    /// publisher may refresh its variables on every input without waking its subscribers for nothing.
    template <class Msg>
    void publish_latest(Msg msg) {
        std::shared_ptr<const Msg> shared;
        std::vector<std::shared_ptr<Subscriber<Msg>>> subs;
        {
            std::lock_guard lock(mutex_);
            auto& topic = topics_[std::type_index(typeid(Msg))];
            if constexpr (std::equality_comparable<Msg>) {
                if (topic.latest.has_value() &&
                    *std::any_cast<std::shared_ptr<const Msg>&>(topic.latest) == msg) {
                    return;
                }
            }
            shared = std::make_shared<const Msg>(std::move(msg));
            topic.latest = shared;
            subs = typed_subscribers<Msg>(topic);
        }
        for (auto& sub : subs) {
            deliver_latest(sub, shared);
        }
    }

    /// The last value published with publish_latest, if any.
    template <class Msg>
    std::optional<Msg> latest() const {
        std::lock_guard lock(mutex_);
        auto it = topics_.find(std::type_index(typeid(Msg)));
        if (it == topics_.end() || !it->second.latest.has_value()) {
            return std::nullopt;
        }
        return *std::any_cast<std::shared_ptr<const Msg>>(it->second.latest);
    }

  private:
    struct SubscriberBase {
        std::shared_ptr<std::atomic<bool>> alive = std::make_shared<std::atomic<bool>>(true);
        virtual ~SubscriberBase() = default;
    };
    template <class Msg>
    struct Subscriber : SubscriberBase {
        Subscriber(Strand s, std::function<void(const Msg&)> h)
            : strand(std::move(s)), handler(std::move(h)) {}
        Strand strand;
        std::function<void(const Msg&)> handler;
        std::mutex pending_mutex;
        std::shared_ptr<const Msg> pending;  // newest undelivered variable value
    };
    struct Topic {
        std::vector<std::shared_ptr<SubscriberBase>> subscribers;
        std::any latest;
    };

    template <class Msg>
    static void deliver_latest(const std::shared_ptr<Subscriber<Msg>>& sub,
                               std::shared_ptr<const Msg> value) {
        bool need_post;
        {
            std::lock_guard lock(sub->pending_mutex);
            need_post = !sub->pending;
            sub->pending = std::move(value);
        }
        if (!need_post) {
            return;  // a delivery is already queued; it will pick up the newest value
        }
        asio::post(sub->strand, [sub] {
            std::shared_ptr<const Msg> v;
            {
                std::lock_guard lock(sub->pending_mutex);
                v = std::move(sub->pending);
                sub->pending.reset();
            }
            if (v && sub->alive->load()) {
                sub->handler(*v);
            }
        });
    }

    static void prune(Topic& topic) {
        std::erase_if(topic.subscribers, [](const auto& s) { return !s->alive->load(); });
    }

    template <class Msg>
    static std::vector<std::shared_ptr<Subscriber<Msg>>> typed_subscribers(Topic& topic) {
        prune(topic);
        std::vector<std::shared_ptr<Subscriber<Msg>>> out;
        out.reserve(topic.subscribers.size());
        for (auto& s : topic.subscribers) {
            out.push_back(std::static_pointer_cast<Subscriber<Msg>>(s));
        }
        return out;
    }

    template <class Msg>
    std::vector<std::shared_ptr<Subscriber<Msg>>> subscribers_of() {
        std::lock_guard lock(mutex_);
        auto it = topics_.find(std::type_index(typeid(Msg)));
        if (it == topics_.end()) {
            return {};
        }
        return typed_subscribers<Msg>(it->second);
    }

    mutable std::mutex mutex_;
    std::map<std::type_index, Topic> topics_;
};

}  // namespace airseg
