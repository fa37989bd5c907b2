#include "groundside/mqtt_session.hpp"

#include <fmt/format.h>
#include <mosquitto.h>

#include <atomic>
#include <charconv>
#include <mutex>
#include <utility>
#include <vector>

#include "base/file_text.hpp"

namespace airseg::groundside {

namespace {
std::once_flag g_library;
}

std::string parse_broker(std::string_view text, MqttOptions& options) {
    if (text.empty()) {
        return "no broker given (HOST or HOST:PORT)";
    }
    const auto colon = text.rfind(':');
    if (colon == std::string_view::npos) {
        options.host = text;
        return {};
    }
    int port = 0;
    const auto digits = text.substr(colon + 1);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (colon == 0 || ec != std::errc() || end != digits.data() + digits.size() || port < 1 || port > 65535) {
        return "broker '" + std::string(text) + "' is not HOST or HOST:PORT with a port 1..65535";
    }
    options.host = text.substr(0, colon);
    options.port = port;
    return {};
}

struct MqttSession::State : std::enable_shared_from_this<MqttSession::State> {
    asio::any_io_executor executor;
    MqttOptions options;
    Handlers handlers;
    mosquitto* mosq = nullptr;
    std::mutex mutex;  // subscriptions: the network thread renews them on connect
    std::vector<std::pair<std::string, int>> subscriptions;
    std::atomic<bool> stopped{false};
    std::atomic<bool> connected{false};  // on the network thread only; atomic for the sanitizers' sake
    bool started = false;

    // libmosquitto's callbacks, on its network thread: hand over to the executor. The state may be gone by
    // then, so the posted work holds a weak reference.
    static void on_connect(mosquitto* m, void* self, int rc) {
        auto* s = static_cast<State*>(self);
        s->connected = rc == 0;
        if (rc == 0) {
            std::lock_guard lock(s->mutex);
            for (const auto& [topic, qos] : s->subscriptions) {
                mosquitto_subscribe(m, nullptr, topic.c_str(), qos);
            }
        }
        s->post_connection(rc == 0, rc == 0 ? "" : mosquitto_connack_string(rc));
    }
    static void on_disconnect(mosquitto*, void* self, int rc) {
        auto* s = static_cast<State*>(self);
        // A refused connection is followed by a disconnect too; the refusal already said why.
        if (s->connected.exchange(false)) {
            s->post_connection(false, rc == 0 ? "disconnected" : "connection lost");
        }
    }
    static void on_message(mosquitto*, void* self, const mosquitto_message* msg) {
        auto* s = static_cast<State*>(self);
        std::string topic(msg->topic);
        std::string payload(static_cast<const char*>(msg->payload),
                            static_cast<std::size_t>(msg->payloadlen));
        asio::post(s->executor,
                   [weak = s->weak_from_this(), topic = std::move(topic), payload = std::move(payload)] {
                       if (auto state = weak.lock(); state && !state->stopped && state->handlers.on_message) {
                           state->handlers.on_message(topic, payload);
                       }
                   });
    }
    void post_connection(bool up, std::string why) {
        asio::post(executor, [weak = weak_from_this(), up, why = std::move(why)] {
            if (auto state = weak.lock(); state && !state->stopped && state->handlers.on_connection) {
                state->handlers.on_connection(up, why);
            }
        });
    }
};

MqttSession::MqttSession(asio::any_io_executor executor, MqttOptions options, Handlers handlers)
    : state_(std::make_shared<State>()) {
    std::call_once(g_library, [] { mosquitto_lib_init(); });
    state_->executor = std::move(executor);
    state_->options = std::move(options);
    state_->handlers = std::move(handlers);
    const auto& o = state_->options;
    state_->mosq =
        mosquitto_new(o.client_id.empty() ? nullptr : o.client_id.c_str(), o.clean_session, state_.get());
    if (state_->mosq != nullptr) {
        mosquitto_int_option(state_->mosq, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
        mosquitto_connect_callback_set(state_->mosq, &State::on_connect);
        mosquitto_disconnect_callback_set(state_->mosq, &State::on_disconnect);
        mosquitto_message_callback_set(state_->mosq, &State::on_message);
        // Back off from 1 s to 10 s between attempts: a restarted broker is found again within seconds.
        mosquitto_reconnect_delay_set(state_->mosq, 1, 10, true);
    }
}

MqttSession::~MqttSession() {
    stop();
    if (state_->mosq != nullptr) {
        mosquitto_destroy(state_->mosq);
    }
}

void MqttSession::set_will(const std::string& topic, const std::string& payload, int qos, bool retain) {
    if (state_->mosq != nullptr) {
        mosquitto_will_set(state_->mosq, topic.c_str(), static_cast<int>(payload.size()), payload.data(), qos,
                           retain);
    }
}

std::string MqttSession::start() {
    auto* m = state_->mosq;
    const auto& o = state_->options;
    if (m == nullptr) {
        return "cannot create an MQTT client (client id '" + o.client_id + "')";
    }
    if (!o.username.empty()) {
        std::string password;
        if (!o.password_file.empty()) {
            const auto file = read_file_text(o.password_file, kMaxSmallFileBytes);
            if (!file.ok()) {
                return "cannot read the MQTT password from " + o.password_file + ": " + file.error;
            }
            password = file.text.substr(0, file.text.find('\n'));
        }
        mosquitto_username_pw_set(m, o.username.c_str(),
                                  o.password_file.empty() ? nullptr : password.c_str());
    }
    if (!o.ca_file.empty()) {
        const int rc = mosquitto_tls_set(m, o.ca_file.c_str(), nullptr,
                                         o.cert_file.empty() ? nullptr : o.cert_file.c_str(),
                                         o.key_file.empty() ? nullptr : o.key_file.c_str(), nullptr);
        if (rc != MOSQ_ERR_SUCCESS) {
            return "MQTT TLS files (" + o.ca_file + (o.cert_file.empty() ? "" : ", " + o.cert_file) +
                   "): " + mosquitto_strerror(rc);
        }
    }
    // A broker that is not there yet is not an error: the network thread keeps trying.
    const int rc = mosquitto_connect_async(m, o.host.c_str(), o.port, o.keepalive_s);
    if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_ERRNO) {
        return fmt::format("MQTT broker {}:{}: {}", o.host, o.port, mosquitto_strerror(rc));
    }
    if (const int loop = mosquitto_loop_start(m); loop != MOSQ_ERR_SUCCESS) {
        return std::string("MQTT network thread: ") + mosquitto_strerror(loop);
    }
    state_->started = true;
    return {};
}

void MqttSession::stop() {
    if (state_->stopped.exchange(true) || state_->mosq == nullptr) {
        return;
    }
    if (state_->started) {
        mosquitto_disconnect(state_->mosq);
        mosquitto_loop_stop(state_->mosq, false);
    }
}

bool MqttSession::publish(const std::string& topic, const std::string& payload, int qos, bool retain) {
    if (state_->stopped || state_->mosq == nullptr) {
        return false;
    }
    const int rc = mosquitto_publish(state_->mosq, nullptr, topic.c_str(), static_cast<int>(payload.size()),
                                     payload.data(), qos, retain);
    // Not connected: QoS 1 and 2 messages stay queued in the library and go out after the reconnect.
    return rc == MOSQ_ERR_SUCCESS || (rc == MOSQ_ERR_NO_CONN && qos > 0);
}

void MqttSession::subscribe(const std::string& topic, int qos) {
    {
        std::lock_guard lock(state_->mutex);
        state_->subscriptions.emplace_back(topic, qos);
    }
    if (state_->mosq != nullptr) {
        mosquitto_subscribe(state_->mosq, nullptr, topic.c_str(),
                            qos);  // fails harmlessly while disconnected
    }
}

}  // namespace airseg::groundside
