#pragma once
// What the link benchmark needs from one end of a link protocol: the common ground of the seed's MAREA serial
// transport and airseg's ground-link transport core, both sans-IO.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"

namespace airseg::linkbench {

struct BenchMessage {
    bool safe = false;
    std::vector<std::uint8_t> bytes;
};

/// How a scenario wires the ends: one radio pair for both directions, or two pairs with each end transmitting
/// on its own pair (the seed's "serialduo", the transport's split mode).
enum class LinkMode : std::uint8_t { Single, Dual };

struct EndpointSetup {
    std::uint32_t baud = 57600;
    LinkMode mode = LinkMode::Single;
    bool is_a = true;  ///< end A transmits on path 0 in dual mode, end B on path 1
    /// Which start of the end's program this is (a client started again is a new process: a new session).
    std::uint32_t incarnation = 0;
    TimePoint now{};
    double pacing_factor = 1.0;  ///< a pacing protocol's link rate as a fraction of baud/10
    /// What the radio does on air, for a protocol that can be told (nullopt: it assumes its defaults).
    struct Radio {
        Duration turnaround{0};
        std::size_t air_packet = 0;
        std::size_t air_packet_overhead = 0;
        std::size_t buffer = 0;
        /// Told the turnaround and packets too (otherwise only the buffer: the rest at its defaults).
        bool told = true;
        /// Pacing follows the air as measured (groundlink.radio.adapt).
        bool adapt = false;
    };
    std::optional<Radio> radio;
};

class BenchEndpoint {
  public:
    virtual ~BenchEndpoint() = default;

    /// False when the protocol refuses the message for now (queue full); the workload retries later.
    virtual bool send_safe(std::span<const std::uint8_t> msg, TimePoint now) = 0;
    /// A Safe message on the protocol's most urgent channel (commands and their answers).
    virtual bool send_urgent(std::span<const std::uint8_t> msg, TimePoint now) = 0;
    /// `stream` tells independent Fast streams apart (a topic, where the protocol has them).
    virtual void send_fast(std::uint16_t stream, std::span<const std::uint8_t> msg, TimePoint now) = 0;
    virtual void handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now) = 0;
    virtual void handle_timeout(TimePoint now) = 0;
    /// One whole frame to write to `path`, or nullopt.
    virtual std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now) = 0;
    virtual std::optional<BenchMessage> poll_message() = 0;
    virtual TimePoint poll_timeout() const = 0;
    /// Safe messages accepted and not yet acknowledged.
    virtual std::size_t safe_backlog() const = 0;

    /// The air as the protocol measured it: payload bytes/s it paces for and the turnaround (ms, -1 when
    /// not measured); nullopt for a protocol that does not measure.
    struct AirMeasure {
        double carried = 0.0;
        double turnaround_ms = -1.0;
    };
    [[nodiscard]] virtual std::optional<AirMeasure> air_measure() const { return std::nullopt; }
    /// Whether the application on this protocol names commands with request ids, which the vehicle's
    /// record of recent commands runs at most once (airseg's ground protocol does; the seed's did not).
    [[nodiscard]] virtual bool request_ids() const { return true; }
};

/// The seed's protocol (bench/linkbench/seed_protocol.hpp).
std::unique_ptr<BenchEndpoint> make_seed_endpoint(const EndpointSetup& setup);

/// airseg's transport core, or nullptr when the benchmark was built without it.
std::unique_ptr<BenchEndpoint> make_transport_endpoint(const EndpointSetup& setup);

}  // namespace airseg::linkbench
