#include "groundside/mqtt_session.hpp"

#include <fmt/format.h>
#include <mosquitto.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509_vfy.h>
#include <openssl/x509v3.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <condition_variable>
#include <cstring>
#include <memory>
#include <mutex>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "base/file_text.hpp"

namespace airseg::groundside {

namespace {

std::once_flag g_library;

/// The reason OpenSSL gives for its latest error ("no start line"), and clears its queue.
std::string openssl_reason() {
    std::string reason;
    while (const auto code = ERR_get_error()) {
        if (reason.empty()) {
            const char* text = ERR_reason_error_string(code);
            reason = text != nullptr ? text : fmt::format("OpenSSL error {:#x}", code);
        }
    }
    return reason.empty() ? "not PEM" : reason;
}

/// The PEM text of a TLS file given by `option`, read by the project's checked reader: an error for people,
/// or empty with `text` filled.
std::string read_pem(const char* option, const std::string& path, std::string& text) {
    const auto file = read_file_text(path, kMaxConfigFileBytes);
    if (!file.ok()) {
        return fmt::format("--{} {}: {}", option, path, file.error);
    }
    text = file.text;
    return {};
}

struct BioDeleter {
    void operator()(BIO* b) const { BIO_free(b); }
};
std::unique_ptr<BIO, BioDeleter> memory_bio(const std::string& text) {
    return std::unique_ptr<BIO, BioDeleter>(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
}

/// An encrypted key would make OpenSSL ask on the terminal: never; it is refused.
int no_passphrase(char*, int, int, void*) {
    return 0;
}

std::string x509_time(const ASN1_TIME* t) {
    std::unique_ptr<BIO, BioDeleter> out(BIO_new(BIO_s_mem()));
    if (!out || t == nullptr || ASN1_TIME_print(out.get(), t) != 1) {
        return "?";
    }
    char* data = nullptr;
    const long n = BIO_get_mem_data(out.get(), &data);
    return std::string(data, static_cast<std::size_t>(n));
}

std::string common_name(X509* cert) {
    char cn[256] = "";
    if (cert == nullptr ||
        X509_NAME_get_text_by_NID(X509_get_subject_name(cert), NID_commonName, cn, sizeof cn) < 0) {
        return "no CN";
    }
    return std::string("CN=") + cn;
}

/// A TLS failure as OpenSSL names it ("sslv3 alert certificate expired"), in words that say whose fault.
std::string tls_alert_text(const std::string& reason) {
    const auto has = [&reason](const char* what) { return reason.find(what) != std::string::npos; };
    if (has("alert certificate expired")) {
        return "the broker refused the client certificate (--mqtt-cert): it has expired (" + reason + ")";
    }
    if (has("alert certificate required")) {
        return "the broker requires a client certificate (--mqtt-cert and --mqtt-key) (" + reason + ")";
    }
    if (has("alert unknown ca")) {
        return "the broker does not know the CA of the client certificate (--mqtt-cert) (" + reason + ")";
    }
    if (has("alert bad certificate") || has("alert certificate unknown") ||
        has("alert unsupported certificate") || has("alert certificate revoked")) {
        return "the broker refused the client certificate (--mqtt-cert) (" + reason + ")";
    }
    return reason;
}

}  // namespace

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
    SSL_CTX* tls = nullptr;
    std::mutex mutex;  // subscriptions: the network thread renews them on connect
    std::vector<std::pair<std::string, int>> subscriptions;
    std::atomic<bool> stopped{false};
    std::atomic<bool> connected{false};  // on the network thread only; atomic for the sanitizers' sake
    std::thread network;
    std::mutex wait_mutex;  // the network thread's pause between attempts, cut short by stop()
    std::condition_variable wake;
    // One connection attempt, on the network thread only: whether it was already reported (a refusal in the
    // CONNACK), and what TLS said about it: our check of the broker's certificate, the broker's alert.
    bool attempt_reported = false;
    std::string verify_failure;
    std::string tls_error;

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
        s->attempt_reported = true;
        s->post_connection(rc == 0, rc == 0 ? "" : mosquitto_connack_string(rc), rc != 0);
    }
    static void on_disconnect(mosquitto*, void* self, int rc) {
        auto* s = static_cast<State*>(self);
        // A refused connection is followed by a disconnect too; the refusal already said why.
        if (s->connected.exchange(false)) {
            s->post_connection(false, rc == 0 ? "disconnected" : "connection lost", false);
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
    // libmosquitto logs OpenSSL's errors ("OpenSSL Error[0]: error:0A000415:SSL routines::sslv3 alert
    // certificate expired"); the first of an attempt is its TLS failure.
    static void on_log(mosquitto*, void* self, int level, const char* text) {
        auto* s = static_cast<State*>(self);
        constexpr std::string_view kOpenSsl = "OpenSSL Error";
        const std::string_view line(text != nullptr ? text : "");
        if (level != MOSQ_LOG_ERR || line.substr(0, kOpenSsl.size()) != kOpenSsl || !s->tls_error.empty()) {
            return;
        }
        const auto reason = line.rfind("::");
        s->tls_error = std::string(reason == std::string_view::npos ? line : line.substr(reason + 2));
    }
    // OpenSSL's check of the broker's certificate: the first failure of an attempt, for people.
    static int on_verify(int ok, X509_STORE_CTX* store) {
        auto* ssl =
            static_cast<SSL*>(X509_STORE_CTX_get_ex_data(store, SSL_get_ex_data_X509_STORE_CTX_idx()));
        auto* s = ssl == nullptr ? nullptr : static_cast<State*>(SSL_CTX_get_app_data(SSL_get_SSL_CTX(ssl)));
        if (ok == 0 && s != nullptr && s->verify_failure.empty()) {
            s->verify_failure = s->describe_verify_failure(store);
        }
        return ok;
    }
    std::string describe_verify_failure(X509_STORE_CTX* store) const {
        const int error = X509_STORE_CTX_get_error(store);
        X509* cert = X509_STORE_CTX_get_current_cert(store);
        X509* leaf = X509_STORE_CTX_get0_cert(store);
        // The broker's own certificate, or a CA certificate it sent along with it.
        const auto which = X509_STORE_CTX_get_error_depth(store) == 0 || cert == leaf
                               ? fmt::format("the broker's certificate ({})", common_name(leaf))
                               : fmt::format("the CA certificate ({}) the broker sent with its own ({})",
                                             common_name(cert), common_name(leaf));
        const std::string reason = X509_verify_cert_error_string(error);
        switch (error) {
            case X509_V_ERR_UNABLE_TO_GET_ISSUER_CERT:
            case X509_V_ERR_UNABLE_TO_GET_ISSUER_CERT_LOCALLY:
            case X509_V_ERR_DEPTH_ZERO_SELF_SIGNED_CERT:
            case X509_V_ERR_SELF_SIGNED_CERT_IN_CHAIN:
            case X509_V_ERR_CERT_SIGNATURE_FAILURE:
            case X509_V_ERR_UNABLE_TO_VERIFY_LEAF_SIGNATURE:
                return fmt::format(
                    "the broker's certificate ({}) is not signed by the CA of --mqtt-ca {} ({}; is it the "
                    "broker's CA?)",
                    common_name(leaf), options.ca_file, reason);
            case X509_V_ERR_CERT_HAS_EXPIRED:
                return fmt::format("{} has expired (valid until {})", which,
                                   x509_time(X509_get0_notAfter(cert)));
            case X509_V_ERR_CERT_NOT_YET_VALID:
                return fmt::format("{} is not valid yet (valid from {}; is this machine's clock right?)",
                                   which, x509_time(X509_get0_notBefore(cert)));
            case X509_V_ERR_HOSTNAME_MISMATCH:
            case X509_V_ERR_IP_ADDRESS_MISMATCH:
                return fmt::format("{} is not for {} (neither its CN nor its subjectAltName names it)", which,
                                   options.host);
            default:
                return fmt::format("{}: {}", which, reason);
        }
    }
    void post_connection(bool up, std::string why, bool definitive) {
        asio::post(executor, [weak = weak_from_this(), up, why = std::move(why), definitive] {
            if (auto state = weak.lock(); state && !state->stopped && state->handlers.on_connection) {
                state->handlers.on_connection(up, why, definitive);
            }
        });
    }

    /// Why an attempt failed with `rc` (and `error`, the errno then), for people; whether it would fail again
    /// the same way.
    std::pair<std::string, bool> failure(int rc, int error) const {
        if (!verify_failure.empty()) {
            return {"TLS handshake failed: " + verify_failure, true};
        }
        if (!tls_error.empty()) {
            return {"TLS handshake failed: " + tls_alert_text(tls_error), true};
        }
        if (rc == MOSQ_ERR_ERRNO) {
            return {std::strerror(error), false};
        }
        return {mosquitto_strerror(rc), rc == MOSQ_ERR_TLS};
    }

    // The network thread: connects, runs the connection, and after a failure or a loss tries again, every
    // 1 s backing off to 10 s. Unlike libmosquitto's own thread, it keeps trying after a TLS failure: a
    // broker's certificate may be renewed while the hub waits.
    void run() {
        auto pause = std::chrono::seconds(1);
        bool first = true;
        while (!stopped) {
            attempt_reported = false;
            verify_failure.clear();
            tls_error.clear();
            errno = 0;
            int rc =
                first ? mosquitto_connect_async(mosq, options.host.c_str(), options.port, options.keepalive_s)
                      : mosquitto_reconnect_async(mosq);
            first = false;
            int error = errno;
            bool was_up = false;
            if (rc == MOSQ_ERR_SUCCESS) {
                for (;;) {
                    rc = mosquitto_loop(mosq, 200, 1);
                    error = errno;
                    was_up = was_up || connected;
                    if (rc != MOSQ_ERR_SUCCESS || (stopped && !connected)) {
                        break;
                    }
                }
            }
            if (stopped) {
                break;
            }
            if (connected.exchange(false)) {
                post_connection(false, "connection lost", false);
            } else if (!attempt_reported && !was_up) {
                auto [why, definitive] = failure(rc, error);
                post_connection(false, why, definitive);
            }
            if (was_up) {
                pause = std::chrono::seconds(1);
            }
            std::unique_lock lock(wait_mutex);
            wake.wait_for(lock, pause, [this] { return stopped.load(); });
            pause = std::min(pause * 2, std::chrono::seconds(10));
        }
    }

    /// The TLS context of --mqtt-ca, --mqtt-cert and --mqtt-key, their files read by the checked reader; an
    /// error for people, empty when fine.
    std::string make_tls() {
        std::string ca, cert, key;
        for (auto [option, path, text] : {std::tuple{"mqtt-ca", &options.ca_file, &ca},
                                          std::tuple{"mqtt-cert", &options.cert_file, &cert},
                                          std::tuple{"mqtt-key", &options.key_file, &key}}) {
            if (!path->empty()) {
                if (auto error = read_pem(option, *path, *text); !error.empty()) {
                    return error;
                }
            }
        }
        ERR_clear_error();
        tls = SSL_CTX_new(TLS_client_method());
        if (tls == nullptr) {
            return "cannot make a TLS context: " + openssl_reason();
        }
        SSL_CTX_set_min_proto_version(tls, TLS1_2_VERSION);
        SSL_CTX_set_app_data(tls, this);
        SSL_CTX_set_default_passwd_cb(tls, &no_passphrase);
        // The broker's CA, and only it.
        int cas = 0;
        {
            auto bio = memory_bio(ca);
            X509_STORE* store = SSL_CTX_get_cert_store(tls);
            while (X509* c = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr)) {
                X509_STORE_add_cert(store, c);
                X509_free(c);
                ++cas;
            }
            ERR_clear_error();  // the end of the text
        }
        if (cas == 0) {
            return fmt::format("--mqtt-ca {}: no PEM certificate in it", options.ca_file);
        }
        if (!cert.empty()) {
            auto bio = memory_bio(cert);
            X509* leaf = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr);
            if (leaf == nullptr || SSL_CTX_use_certificate(tls, leaf) != 1) {
                X509_free(leaf);
                return fmt::format("--mqtt-cert {}: not a PEM certificate ({})", options.cert_file,
                                   openssl_reason());
            }
            X509_free(leaf);
            while (X509* c = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr)) {
                SSL_CTX_add0_chain_cert(tls, c);  // intermediates after the certificate
            }
            ERR_clear_error();
            auto key_bio = memory_bio(key);
            EVP_PKEY* pkey = PEM_read_bio_PrivateKey(key_bio.get(), nullptr, &no_passphrase, nullptr);
            if (pkey == nullptr) {
                return fmt::format("--mqtt-key {}: not an unencrypted PEM private key ({})", options.key_file,
                                   openssl_reason());
            }
            if (SSL_CTX_use_PrivateKey(tls, pkey) != 1) {
                EVP_PKEY_free(pkey);
                return fmt::format("--mqtt-key {} is not the key of --mqtt-cert {} ({})", options.key_file,
                                   options.cert_file, openssl_reason());
            }
            EVP_PKEY_free(pkey);
            if (SSL_CTX_check_private_key(tls) != 1) {
                ERR_clear_error();
                return fmt::format("--mqtt-key {} is not the key of --mqtt-cert {}", options.key_file,
                                   options.cert_file);
            }
        }
        // The broker's certificate must chain to the CA and name the host we dial (CN or subjectAltName).
        SSL_CTX_set_verify(tls, SSL_VERIFY_PEER, &State::on_verify);
        X509_VERIFY_PARAM* param = SSL_CTX_get0_param(tls);
        if (X509_VERIFY_PARAM_set1_ip_asc(param, options.host.c_str()) != 1) {
            ERR_clear_error();
            X509_VERIFY_PARAM_set_hostflags(param, X509_CHECK_FLAG_NO_PARTIAL_WILDCARDS);
            X509_VERIFY_PARAM_set1_host(param, options.host.c_str(), 0);
        }
        mosquitto_int_option(mosq, MOSQ_OPT_SSL_CTX_WITH_DEFAULTS, 0);
        if (const int rc = mosquitto_void_option(mosq, MOSQ_OPT_SSL_CTX, tls); rc != MOSQ_ERR_SUCCESS) {
            return std::string("MQTT TLS: ") + mosquitto_strerror(rc);
        }
        return {};
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
        mosquitto_threaded_set(state_->mosq, true);  // our own network thread
        mosquitto_connect_callback_set(state_->mosq, &State::on_connect);
        mosquitto_disconnect_callback_set(state_->mosq, &State::on_disconnect);
        mosquitto_message_callback_set(state_->mosq, &State::on_message);
        mosquitto_log_callback_set(state_->mosq, &State::on_log);
    }
}

MqttSession::~MqttSession() {
    stop();
    if (state_->mosq != nullptr) {
        mosquitto_destroy(state_->mosq);
    }
    if (state_->tls != nullptr) {
        SSL_CTX_free(state_->tls);
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
        if (auto error = state_->make_tls(); !error.empty()) {
            return error;
        }
    }
    // A broker that is not there yet is not an error: the network thread keeps trying.
    state_->network = std::thread([state = state_.get()] { state->run(); });
    return {};
}

void MqttSession::stop() {
    if (state_->stopped.exchange(true) || state_->mosq == nullptr) {
        return;
    }
    if (state_->network.joinable()) {
        mosquitto_disconnect(state_->mosq);
        { std::lock_guard lock(state_->wait_mutex); }
        state_->wake.notify_all();
        state_->network.join();
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
