#include "client/radio_client.hpp"

#include <fmt/format.h>

#include <optional>
#include <random>
#include <sstream>

namespace airseg::client {

namespace gl = airseg::groundlink;
namespace proto = airseg::groundlink::protocol;

class RadioClient::Impl {
  public:
    explicit Impl(groundside::RadioOptions options)
        : strand_(asio::make_strand(io_)),
          end_(strand_, std::move(options),
               groundside::GroundEnd::Handlers{[this](proto::Message m) { on_message(std::move(m)); }, {}}) {
        std::random_device rd;
        next_id_ = rd();  // answers left over from another client's session are not mistaken for ours
    }

    std::string open() { return end_.open(); }

    LocalAnswer request(const nlohmann::json& req, std::chrono::milliseconds timeout,
                        const VehicleLink::MessageHandler& on_message) {
        on_message_ = on_message;  // the pushes while it waits, as run_for sees them
        LocalAnswer out = exchange(req, timeout);
        on_message_ = nullptr;
        return out;
    }

    LocalAnswer exchange(const nlohmann::json& req, std::chrono::milliseconds timeout) {
        LocalAnswer out;
        const std::uint32_t id = next_id_++;
        std::optional<nlohmann::json> answer;
        awaiting_ = id;
        answer_ = &answer;
        std::optional<std::string> not_sent;
        asio::dispatch(strand_, [this, id, req, &not_sent] {
            const proto::Message command = proto::Command{id, req};
            const auto r = end_.send_safe(proto::kPriorityControl, command);
            if (r == gl::SendResult::TooLarge) {
                not_sent = fmt::format(
                    "the command is {} bytes, more than the link carries in one message ({} "
                    "bytes); not sent",
                    proto::encode(command).size(), end_.max_message_size());
            } else if (r != gl::SendResult::Accepted) {
                not_sent =
                    fmt::format("the command could not be queued ({})", (std::ostringstream{} << r).str());
            }
        });
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        std::string refused;
        while (!answer && !not_sent && refused.empty() && std::chrono::steady_clock::now() < deadline) {
            io_.run_for(std::chrono::milliseconds(20));
            if (io_.stopped()) {
                io_.restart();
            }
            refused = end_.authorisation_problem();
        }
        answer_ = nullptr;
        if (!answer && !refused.empty()) {
            out.error = refused;
            return out;
        }
        if (not_sent) {
            // Refused here, before the air: answered as the vehicle answers a request it cannot take.
            out.answer = nlohmann::json{{"ok", false}, {"status", "bad_request"}, {"error", *not_sent}};
            return out;
        }
        if (!answer) {
            out.error = fmt::format("no answer from the vehicle within {} ms ({})", timeout.count(),
                                    end_.link_up() ? "link up" : "no link");
            return out;
        }
        // Let our acknowledgement of the answer reach the vehicle before the caller exits.
        io_.run_for(std::chrono::milliseconds(300));
        io_.restart();
        out.answer = std::move(answer);
        return out;
    }

    void run_for(std::chrono::milliseconds d, const std::function<void(const proto::Message&)>& on_message) {
        on_message_ = on_message;
        io_.run_for(d);
        io_.restart();
        on_message_ = nullptr;
    }

    groundside::GroundEnd& end() { return end_; }
    const groundside::GroundEnd& end() const { return end_; }

    void send_joystick(double steering, double throttle) {
        asio::dispatch(strand_, [this, steering, throttle] {
            end_.send_fast(proto::kPriorityControl, proto::kTopicJoystick,
                           proto::Joystick{steering, throttle});
        });
    }

  private:
    void on_message(proto::Message m) {
        if (auto* result = std::get_if<proto::Result>(&m)) {
            if (answer_ != nullptr && result->request_id == awaiting_) {
                *answer_ = result->answer;
            }
            return;
        }
        if (on_message_) {
            on_message_(m);
        }
    }

    asio::io_context io_;
    Strand strand_;
    groundside::GroundEnd end_;
    std::uint32_t next_id_ = 1;
    std::uint32_t awaiting_ = 0;
    std::optional<nlohmann::json>* answer_ = nullptr;
    std::function<void(const proto::Message&)> on_message_;
};

RadioClient::RadioClient(groundside::RadioOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {}
RadioClient::~RadioClient() = default;
std::string RadioClient::open() {
    return impl_->open();
}
LocalAnswer RadioClient::request(const nlohmann::json& r, std::chrono::milliseconds t,
                                 const MessageHandler& f) {
    return impl_->request(r, t, f);
}
void RadioClient::run_for(std::chrono::milliseconds d, const std::function<void(const proto::Message&)>& f) {
    impl_->run_for(d, f);
}
nlohmann::json RadioClient::link_stats() const {
    return impl_->end().link_stats();
}
bool RadioClient::link_up() const {
    return impl_->end().link_up();
}
void RadioClient::send_joystick(double steering, double throttle) {
    impl_->send_joystick(steering, throttle);
}
std::uint64_t RadioClient::bytes_sent() const {
    return impl_->end().bytes_sent();
}

}  // namespace airseg::client
