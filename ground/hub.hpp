#pragma once
// airseg-ground's hub: owns the radio link (one ground-link session to the vehicle) and serves many local
// clients on a Unix socket and, optionally, TCP. Every client sees what the vehicle pushes; commands are
// relayed one by one, each answered end to end by the vehicle. Roles per client: one control client at a time
// (it proved the control key, or came over the Unix socket of a hub without a key) and any number of
// monitors, whose commands the vehicle runs with monitor rights only.
#include <boost/asio/local/stream_protocol.hpp>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "ground/client_connection.hpp"
#include "groundside/ground_end.hpp"
#include "groundside/hub_wire.hpp"
#include "services/common/asio.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::ground {

struct HubConfig {
    groundside::RadioOptions radio;
    std::string socket{groundside::hub::kDefaultSocket};  // empty = no Unix socket
    std::string tcp;                                      // HOST:PORT; empty = no TCP listener
    std::string socket_group;  // group given access to the Unix socket; empty = the hub's own
};

class Hub {
  public:
    /// Clients at once (Unix socket and TCP together); a connection beyond is closed with an error line.
    static constexpr std::size_t kMaxClients = 64;
    /// A client that has not said hello this long after connecting is closed.
    static constexpr auto kHelloTimeout = std::chrono::seconds(10);
    /// Commands relayed and not yet answered, all clients together; a command beyond is answered busy.
    static constexpr std::size_t kMaxPending = 256;

    /// The vehicle's answer to a command the hub itself sent (the map's buttons, the plan shape).
    using Done = std::function<void(nlohmann::json answer)>;
    /// Everything the vehicle pushes, for the hub's own consumers (the map, the MAVLink endpoint).
    using Listener = std::function<void(const groundlink::protocol::Message&)>;
    /// The name of each relayed command ("plan.load") and the vehicle's answer to it.
    using ResultListener = std::function<void(const std::string& cmd, const nlohmann::json& answer)>;
    /// The link's events (up, down, the vehicle's end restarted).
    using LinkListener = std::function<void(const groundlink::TransportEvent& event)>;
    /// Adds counters of the hub's parts to its link statistics.
    using StatsSource = std::function<void(nlohmann::json& stats)>;

    Hub(Strand strand, HubConfig config);
    ~Hub();
    Hub(const Hub&) = delete;
    Hub& operator=(const Hub&) = delete;

    /// Opens the radio and the listeners; an error for people, empty on success.
    std::string start();
    void stop();

    // On the strand:
    /// Sends a command with control rights on behalf of the hub itself.
    void command(nlohmann::json request, Done done);
    void add_listener(Listener listener) { listeners_.push_back(std::move(listener)); }
    void add_result_listener(ResultListener listener) { result_listeners_.push_back(std::move(listener)); }
    void add_link_listener(LinkListener listener) { link_listeners_.push_back(std::move(listener)); }
    void add_stats_source(StatsSource source) { stats_sources_.push_back(std::move(source)); }
    /// Sends a message to the vehicle reliably (MAVLink from ground stations).
    groundlink::SendResult send_to_vehicle(const groundlink::protocol::Message& message);
    nlohmann::json link_stats() const;
    std::size_t clients() const { return clients_.size(); }

  private:
    struct ClientState {
        std::shared_ptr<ClientConnection> connection;
        std::chrono::steady_clock::time_point connected;
        bool timed_out = false;  // closed for saying no hello in time
        std::array<std::uint8_t, groundside::hub::kChallengeBytes> challenge{};
        bool local = false;  // came over the Unix socket
        bool welcomed = false;
        bool control = false;
        bool joystick_warned = false;
        std::string name;
    };
    struct Pending {
        std::uint32_t client = 0;  // 0: the hub's own command
        std::uint32_t client_request = 0;
        Done done;
        std::chrono::steady_clock::time_point sent;
        std::string cmd;
    };

    std::string listen_unix();
    std::string listen_tcp();
    void accept_unix();
    void accept_tcp();
    void add_client(ClientConnection::Socket socket, std::string peer, bool local);
    void retry_accept(std::function<void()> accept);
    void on_frame(ClientConnection& connection, groundside::hub::Frame frame);
    void on_hello(ClientState& client, const nlohmann::json& hello);
    void on_client_message(ClientState& client, const groundlink::protocol::Message& message);
    void on_closed(ClientConnection& connection, const std::string& why);
    void on_vehicle(groundlink::protocol::Message message);
    std::uint32_t relay(nlohmann::json request, Pending pending);
    void broadcast(const std::vector<std::uint8_t>& frame);
    void tick();

    Strand strand_;
    HubConfig config_;
    groundside::GroundEnd end_;
    std::optional<std::array<std::uint8_t, 32>> key_;
    std::unique_ptr<asio::local::stream_protocol::acceptor> unix_acceptor_;
    std::unique_ptr<asio::ip::tcp::acceptor> tcp_acceptor_;
    asio::steady_timer tick_timer_;
    std::map<std::uint32_t, ClientState> clients_;
    std::map<std::uint32_t, Pending> pending_;
    std::vector<Listener> listeners_;
    std::vector<ResultListener> result_listeners_;
    std::vector<LinkListener> link_listeners_;
    std::vector<StatsSource> stats_sources_;
    std::uint32_t next_client_ = 1;
    std::uint32_t next_request_ = 1;
    std::uint32_t control_holder_ = 0;
    bool stopped_ = false;
    asio::steady_timer accept_retry_;
    LimitedLog log_;                     // every line a client or the vehicle can make the hub write
    std::uint64_t clients_refused_ = 0;  // connections closed at once: kMaxClients already connected
    std::uint64_t hello_timeouts_ = 0;   // clients closed for not saying hello within kHelloTimeout
    std::uint64_t commands_busy_ = 0;    // commands answered busy: kMaxPending already waiting
};

}  // namespace airseg::ground
