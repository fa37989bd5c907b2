#include "ground/hub.hpp"

#include <fmt/format.h>
#include <grp.h>
#include <sodium.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "services/common/printable.hpp"
#include "services/groundlink/link/key_file.hpp"

namespace airseg::ground {

namespace proto = groundlink::protocol;
namespace hub = groundside::hub;
using Json = nlohmann::json;

namespace {
/// How long the hub remembers a relayed command the vehicle has not answered (the client gave up long
/// before).
constexpr auto kForgetUnanswered = std::chrono::minutes(10);
/// How long the hub waits for the answer to a command of its own (the map's) before calling it unanswered.
constexpr auto kOwnCommandPatience = std::chrono::seconds(60);

std::pair<std::string, std::string> split_host_port(const std::string& text) {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos) {
        return {};
    }
    return {text.substr(0, colon), text.substr(colon + 1)};
}
}  // namespace

Hub::Hub(Strand strand, HubConfig config)
    : strand_(std::move(strand)),
      config_(std::move(config)),
      end_(strand_, config_.radio,
           groundside::GroundEnd::Handlers{[this](proto::Message m) { on_vehicle(std::move(m)); },
                                           [this](const groundlink::TransportEvent& e) {
                                               using Kind = groundlink::TransportEvent::Kind;
                                               const auto now = std::chrono::steady_clock::now();
                                               if (e.kind == Kind::LinkUp) {
                                                   log_.log("ground hub: link up", now, spdlog::level::info,
                                                            "ground hub: link to the vehicle up");
                                               } else if (e.kind == Kind::LinkDown) {
                                                   log_.log("ground hub: link down", now, spdlog::level::warn,
                                                            "ground hub: link to the vehicle down");
                                               }
                                               for (const auto& listener : link_listeners_) {
                                                   listener(e);
                                               }
                                           }}),
      tick_timer_(strand_),
      accept_retry_(strand_) {}

Hub::~Hub() {
    stop();
}

std::string Hub::start() {
    if (!config_.radio.key_file.empty()) {
        auto key = groundlink::read_key_file(config_.radio.key_file);
        if (!key.key) {
            return key.error;
        }
        key_ = key.key;
    }
    if (auto error = end_.open(); !error.empty()) {
        return error;
    }
    if (!config_.socket.empty()) {
        if (auto error = listen_unix(); !error.empty()) {
            return error;
        }
    }
    if (!config_.tcp.empty()) {
        if (auto error = listen_tcp(); !error.empty()) {
            return error;
        }
    }
    tick();
    return {};
}

void Hub::stop() {
    if (stopped_) {
        return;
    }
    stopped_ = true;
    tick_timer_.cancel();
    accept_retry_.cancel();
    boost::system::error_code ignored;
    if (unix_acceptor_) {
        unix_acceptor_->close(ignored);
        std::error_code gone;
        std::filesystem::remove(config_.socket, gone);
    }
    if (tcp_acceptor_) {
        tcp_acceptor_->close(ignored);
    }
    for (auto& [id, client] : clients_) {
        client.connection->close("the ground hub is stopping");
    }
    end_.stop();
}

std::string Hub::listen_unix() {
    const auto& path = config_.socket;
    // A socket file left by a hub that died is removed; one a running hub answers on is not taken over.
    if (std::filesystem::exists(path)) {
        asio::local::stream_protocol::socket probe(strand_);
        boost::system::error_code ec;
        probe.connect(asio::local::stream_protocol::endpoint(path), ec);
        if (!ec) {
            return "another airseg-ground already serves " + path;
        }
        std::error_code stale;
        std::filesystem::remove(path, stale);
    }
    std::error_code made;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), made);
    boost::system::error_code ec;
    unix_acceptor_ = std::make_unique<asio::local::stream_protocol::acceptor>(strand_);
    unix_acceptor_->open(asio::local::stream_protocol(), ec);
    if (!ec) {
        unix_acceptor_->bind(asio::local::stream_protocol::endpoint(path), ec);
    }
    if (!ec) {
        unix_acceptor_->listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        return "cannot listen on " + path + ": " + ec.message();
    }
    // Owner and group: the Unix socket of a hub without a key grants control, so others may not connect.
    ::chmod(path.c_str(), 0660);
    if (!config_.socket_group.empty()) {
        const ::group* g = ::getgrnam(config_.socket_group.c_str());
        if (g == nullptr) {
            return "--socket-group: no group '" + config_.socket_group + "'";
        }
        if (::chown(path.c_str(), static_cast<uid_t>(-1), g->gr_gid) != 0) {
            return "cannot give group " + config_.socket_group + " the socket " + path + ": " +
                   std::strerror(errno);
        }
    }
    spdlog::info("ground hub: clients on {}", path);
    accept_unix();
    return {};
}

std::string Hub::listen_tcp() {
    const auto [host, port] = split_host_port(config_.tcp);
    if (host.empty() || port.empty()) {
        return "--tcp needs HOST:PORT, got '" + config_.tcp + "'";
    }
    boost::system::error_code ec;
    asio::ip::tcp::resolver resolver(strand_);
    auto found = resolver.resolve(host, port, ec);
    if (ec || found.empty()) {
        return "cannot resolve " + config_.tcp + ": " + ec.message();
    }
    tcp_acceptor_ = std::make_unique<asio::ip::tcp::acceptor>(strand_);
    const auto endpoint = found.begin()->endpoint();
    tcp_acceptor_->open(endpoint.protocol(), ec);
    if (!ec) {
        tcp_acceptor_->set_option(asio::socket_base::reuse_address(true), ec);
        tcp_acceptor_->bind(endpoint, ec);
    }
    if (!ec) {
        tcp_acceptor_->listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        return "cannot listen on " + config_.tcp + ": " + ec.message();
    }
    const auto bound = tcp_acceptor_->local_endpoint(ec);
    spdlog::info("ground hub: clients on tcp {}:{}", bound.address().to_string(), bound.port());
    accept_tcp();
    return {};
}

void Hub::accept_unix() {
    unix_acceptor_->async_accept(
        [this](boost::system::error_code ec, asio::local::stream_protocol::socket s) {
            if (stopped_) {
                return;
            }
            if (!ec) {
                add_client(ClientConnection::Socket(std::move(s)), "unix", true);
                accept_unix();
                return;
            }
            // Out of descriptors, say: try again shortly, not in a spin.
            log_.log("ground hub: accept on the unix socket", std::chrono::steady_clock::now(),
                     spdlog::level::warn, "ground hub: accept on {}: {}", config_.socket, ec.message());
            retry_accept([this] { accept_unix(); });
        });
}

void Hub::accept_tcp() {
    tcp_acceptor_->async_accept([this](boost::system::error_code ec, asio::ip::tcp::socket s) {
        if (stopped_) {
            return;
        }
        if (!ec) {
            boost::system::error_code ignored;
            const auto remote = s.remote_endpoint(ignored);
            s.set_option(asio::ip::tcp::no_delay(true), ignored);
            add_client(ClientConnection::Socket(std::move(s)),
                       fmt::format("tcp {}:{}", remote.address().to_string(), remote.port()), false);
            accept_tcp();
            return;
        }
        log_.log("ground hub: accept on tcp", std::chrono::steady_clock::now(), spdlog::level::warn,
                 "ground hub: accept on {}: {}", config_.tcp, ec.message());
        retry_accept([this] { accept_tcp(); });
    });
}

void Hub::retry_accept(std::function<void()> accept) {
    accept_retry_.expires_after(std::chrono::milliseconds(100));
    accept_retry_.async_wait([this, accept = std::move(accept)](boost::system::error_code ec) {
        if (!ec && !stopped_) {
            accept();
        }
    });
}

void Hub::add_client(ClientConnection::Socket socket, std::string peer, bool local) {
    if (clients_.size() >= kMaxClients) {
        ++clients_refused_;
        log_.log("ground hub: refused a client", std::chrono::steady_clock::now(), spdlog::level::warn,
                 "ground hub: refused a client ({}): {} already connected", peer, kMaxClients);
        // Best effort and never blocking: the client's first read says why.
        const auto frame = hub::encode_json(
            {{"error", fmt::format("the ground hub has {} clients already; try again later", kMaxClients)}});
        boost::system::error_code ignored;
        socket.non_blocking(true, ignored);
        socket.write_some(asio::buffer(frame), ignored);
        return;
    }
    const std::uint32_t id = next_client_++;
    ClientState state;
    state.connected = std::chrono::steady_clock::now();
    state.local = local;
    state.name = peer;
    randombytes_buf(state.challenge.data(), state.challenge.size());
    state.connection = std::make_shared<ClientConnection>(
        std::move(socket), id, std::move(peer),
        ClientConnection::Handlers{
            [this](ClientConnection& c, hub::Frame f) { on_frame(c, std::move(f)); },
            [this](ClientConnection& c, const std::string& why) { on_closed(c, why); }});
    auto connection = state.connection;
    clients_.emplace(id, std::move(state));
    connection->send(hub::encode_json({{"hub", "airseg-ground"},
                                       {"version", 1},
                                       {"challenge", hub::to_hex(clients_[id].challenge)},
                                       {"keyed", key_.has_value()},
                                       {"link", end_.link_up() ? "up" : "down"}}));
    connection->start();
}

void Hub::on_frame(ClientConnection& connection, hub::Frame frame) {
    auto it = clients_.find(connection.id());
    if (it == clients_.end()) {
        return;
    }
    ClientState& client = it->second;
    if (frame.type == hub::FrameType::Json) {
        auto j = Json::parse(frame.payload, nullptr, false);
        if (!j.is_object()) {
            connection.close("a hub message that is not a JSON object");
            return;
        }
        if (j.contains("hello") && j["hello"].is_object() && !client.welcomed) {
            on_hello(client, j["hello"]);
            return;
        }
        connection.close("unexpected hub message " +
                         j.dump(-1, ' ', false, Json::error_handler_t::replace).substr(0, 80));
        return;
    }
    if (!client.welcomed) {
        connection.close("a client says hello before anything else");
        return;
    }
    auto decoded = proto::decode(frame.payload);
    if (!decoded.message) {
        // A broken message from a local client is answered, not relayed: the radio is not spent on it.
        connection.send(
            hub::encode_json({{"warning", "ground-protocol message not relayed: " + decoded.error}}));
        return;
    }
    on_client_message(client, *decoded.message);
}

void Hub::on_hello(ClientState& client, const Json& hello) {
    const auto want = hello.value("want", std::string("monitor"));
    if (want != "control" && want != "monitor") {
        client.connection->close("hello: \"want\" must be \"control\" or \"monitor\", got \"" + want + "\"");
        return;
    }
    if (hello.contains("name") && hello["name"].is_string()) {
        // Escaped: the name goes to the hub's log and to every client's link report.
        client.name = printable(hello["name"].get<std::string>().substr(0, 64)) + " (" +
                      client.connection->peer() + ")";
    }
    bool proven = false;
    std::string reason;
    if (key_) {
        const auto given = hello.contains("proof") && hello["proof"].is_string()
                               ? hub::from_hex(hello["proof"].get<std::string>())
                               : std::nullopt;
        const auto expected = hub::proof(*key_, client.challenge);
        proven = given && given->size() == expected.size() &&
                 sodium_memcmp(given->data(), expected.data(), expected.size()) == 0;
        if (!proven) {
            reason = given ? "the key does not match the hub's control key" : "no key given (--key)";
        }
    } else {
        proven = client.local;
        if (!proven) {
            reason = "the hub has no key, so only its Unix socket grants control";
        }
    }
    if (want == "control" && proven) {
        if (control_holder_ == 0) {
            control_holder_ = client.connection->id();
            client.control = true;
        } else {
            reason = "control is held by " + clients_[control_holder_].name;
        }
    }
    client.welcomed = true;
    Json welcome{{"role", client.control ? "control" : "monitor"}, {"client", client.connection->id()}};
    if (want == "control" && !client.control) {
        welcome["reason"] = reason;
    }
    client.connection->send(hub::encode_json({{"welcome", welcome}}));
    client.connection->send(hub::encode_json({{"link", link_stats()}}));
    log_.log("ground hub: client welcomed", std::chrono::steady_clock::now(), spdlog::level::info,
             "ground hub: client {} {} as {}{}", client.connection->id(), client.name,
             client.control ? "control" : "monitor", reason.empty() ? "" : " (" + reason + ")");
}

void Hub::on_client_message(ClientState& client, const proto::Message& message) {
    if (const auto* command = std::get_if<proto::Command>(&message)) {
        auto request = command->request;
        if (!client.control && request.is_object()) {
            // The vehicle stays the one judge of what a monitor may do; the hub only lowers the rights.
            request["role"] = "monitor";
        }
        relay(std::move(request), Pending{client.connection->id(), command->request_id, {}, {}, {}});
    } else if (const auto* stick = std::get_if<proto::Joystick>(&message)) {
        if (!client.control) {
            if (!client.joystick_warned) {
                client.joystick_warned = true;
                client.connection->send(
                    hub::encode_json({{"warning", "joystick input needs the control role; not relayed"}}));
            }
            return;
        }
        end_.send_fast(proto::kPriorityControl, proto::kTopicJoystick, *stick);
    } else {
        // Reception reports and the rest belong to the hub's own session with the vehicle.
        client.connection->send(
            hub::encode_json({{"warning", "only commands and joystick input are relayed"}}));
    }
}

std::uint32_t Hub::relay(Json request, Pending pending) {
    const std::uint32_t id = next_request_++;
    const bool busy = pending_.size() >= kMaxPending;
    const auto r = busy ? groundlink::SendResult::QueueFull
                        : end_.send_safe(proto::kPriorityControl, proto::Command{id, request});
    if (r != groundlink::SendResult::Accepted) {
        std::string error =
            busy ? fmt::format("{} commands already wait for the vehicle's answer; not sent", kMaxPending)
            : r == groundlink::SendResult::TooLarge
                ? fmt::format("the command is more than the link carries in one message ({} bytes); not sent",
                              end_.max_message_size())
                : fmt::format("the command could not be queued ({})", static_cast<int>(r));
        commands_busy_ += busy ? 1 : 0;
        Json answer{{"ok", false}, {"status", busy ? "failed" : "bad_request"}, {"error", error}};
        if (pending.done) {
            pending.done(answer);
        } else if (auto it = clients_.find(pending.client); it != clients_.end()) {
            it->second.connection->send(hub::encode(
                hub::FrameType::Ground, proto::encode(proto::Result{pending.client_request, answer})));
        }
        return id;
    }
    pending.sent = std::chrono::steady_clock::now();
    pending.cmd = request.is_object() ? request.value("cmd", std::string{}) : std::string{};
    pending_.emplace(id, std::move(pending));
    return id;
}

void Hub::command(Json request, Done done) {
    relay(std::move(request), Pending{0, 0, std::move(done), {}, {}});
}

groundlink::SendResult Hub::send_to_vehicle(const proto::Message& message) {
    return end_.send_safe(proto::kPriorityControl, message);
}

void Hub::on_closed(ClientConnection& connection, const std::string& why) {
    auto it = clients_.find(connection.id());
    if (it == clients_.end()) {
        return;
    }
    log_.log("ground hub: client left", std::chrono::steady_clock::now(), spdlog::level::info,
             "ground hub: client {} {} left: {}", connection.id(), it->second.name, why);
    if (control_holder_ == connection.id()) {
        control_holder_ = 0;
    }
    clients_.erase(it);
}

void Hub::on_vehicle(proto::Message message) {
    if (auto* result = std::get_if<proto::Result>(&message)) {
        auto it = pending_.find(result->request_id);
        if (it == pending_.end()) {
            return;  // an answer to an earlier hub session, or one already given up on
        }
        Pending pending = std::move(it->second);
        pending_.erase(it);
        for (const auto& listener : result_listeners_) {
            listener(pending.cmd, result->answer);
        }
        if (pending.done) {
            pending.done(result->answer);
        } else if (auto client = clients_.find(pending.client); client != clients_.end()) {
            client->second.connection->send(
                hub::encode(hub::FrameType::Ground,
                            proto::encode(proto::Result{pending.client_request, result->answer})));
        }
    } else if (!std::holds_alternative<proto::MavlinkFrames>(message)) {
        // The autopilot's own MAVLink is for ground stations (GcsFeed), not for the hub's clients.
        broadcast(hub::encode(hub::FrameType::Ground, proto::encode(message)));
    }
    for (const auto& listener : listeners_) {
        listener(message);
    }
}

void Hub::broadcast(const std::vector<std::uint8_t>& frame) {
    // Copied out first: a client that overflows is dropped from clients_ while we walk.
    std::vector<std::shared_ptr<ClientConnection>> targets;
    for (auto& [id, client] : clients_) {
        if (client.welcomed) {
            targets.push_back(client.connection);
        }
    }
    for (auto& target : targets) {
        target->send(frame);
    }
}

Json Hub::link_stats() const {
    auto stats = end_.link_stats();
    stats["hub_clients"] = clients_.size();
    stats["hub_clients_refused"] = clients_refused_;
    stats["hub_hello_timeouts"] = hello_timeouts_;
    stats["hub_commands_busy"] = commands_busy_;
    if (auto it = clients_.find(control_holder_); it != clients_.end()) {
        stats["control_client"] = it->second.name;
    } else {
        stats["control_client"] = nullptr;
    }
    for (const auto& source : stats_sources_) {
        source(stats);
    }
    return stats;
}

void Hub::tick() {
    if (stopped_) {
        return;
    }
    broadcast(hub::encode_json({{"link", link_stats()}}));
    const auto now = std::chrono::steady_clock::now();
    if (const auto why = end_.authorisation_problem(); !why.empty()) {
        log_.log("ground hub: not authorised", now, spdlog::level::warn, "ground hub: {}", why);
    }
    log_.flush(now);
    std::vector<std::shared_ptr<ClientConnection>> silent;
    for (auto& [id, client] : clients_) {
        if (!client.welcomed && !client.timed_out && now - client.connected > kHelloTimeout) {
            client.timed_out = true;  // closing: its error line may still be on its way
            silent.push_back(client.connection);
        }
    }
    for (const auto& connection : silent) {
        ++hello_timeouts_;
        connection->close(fmt::format("no hello within {} s", kHelloTimeout.count()));
    }
    for (auto it = pending_.begin(); it != pending_.end();) {
        auto& p = it->second;
        if (now - p.sent <= (p.done ? kOwnCommandPatience : kForgetUnanswered)) {
            ++it;
            continue;
        }
        auto done = std::move(p.done);
        it = pending_.erase(it);
        if (done) {
            done(Json{{"ok", false}, {"status", "no_link"}, {"error", "no answer from the vehicle"}});
        }
    }
    tick_timer_.expires_after(std::chrono::seconds(1));
    tick_timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec) {
            tick();
        }
    });
}

}  // namespace airseg::ground
