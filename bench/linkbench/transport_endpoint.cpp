#include "bench/linkbench/endpoint.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::linkbench {

namespace {

// Priorities as the ground link uses them: Fast telemetry on 1, bulk Safe transfers on the lowest (3).
constexpr std::uint8_t kCommandPriority = 0;
constexpr std::uint8_t kFastPriority = 1;
constexpr std::uint8_t kBulkPriority = 3;

groundlink::TransportConfig bench_config(const EndpointSetup& setup) {
    groundlink::TransportConfig c;
    c.link_rate_bytes_per_s = setup.pacing_factor * setup.baud / 10.0;
    c.half_duplex = true;
    if (setup.radio) {
        if (setup.radio->told) {
            c.air_turnaround = setup.radio->turnaround;
            c.air_packet_payload = setup.radio->air_packet;
            c.air_packet_overhead = setup.radio->air_packet_overhead;
        }
        c.radio_buffer_bytes = setup.radio->buffer;
        c.air_adapt = setup.radio->adapt;
    }
    if (setup.mode == LinkMode::Dual) {
        c.paths = 2;
        c.path_mode = groundlink::PathMode::Split;
        c.split_tx_path = setup.is_a ? 0 : 1;
    }
    c.boot_nonce = (setup.is_a ? 0xA11CE : 0xB0B) + 0x10000ULL * setup.incarnation;
    return c;
}

class TransportBenchEndpoint final : public BenchEndpoint {
  public:
    explicit TransportBenchEndpoint(const EndpointSetup& setup) : core_(bench_config(setup), setup.now) {}

    bool send_safe(std::span<const std::uint8_t> msg, TimePoint now) override {
        const auto r = core_.send_safe(kBulkPriority, msg, now);
        return r == groundlink::SendResult::Accepted;
    }
    bool send_urgent(std::span<const std::uint8_t> msg, TimePoint now) override {
        return core_.send_safe(kCommandPriority, msg, now) == groundlink::SendResult::Accepted;
    }
    void send_fast(std::uint16_t stream, std::span<const std::uint8_t> msg, TimePoint now) override {
        core_.send_fast(kFastPriority, stream, msg, now);
    }
    void handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now) override {
        core_.handle_bytes(path, bytes, now);
        drain_events();
    }
    void handle_timeout(TimePoint now) override {
        core_.handle_timeout(now);
        drain_events();
    }
    std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now) override {
        return core_.poll_transmit(path, now);
    }
    std::optional<BenchMessage> poll_message() override {
        auto m = core_.poll_message();
        if (!m) {
            return std::nullopt;
        }
        return BenchMessage{m->cls == groundlink::MessageClass::Safe, std::move(m->bytes)};
    }
    TimePoint poll_timeout() const override { return core_.poll_timeout(); }
    std::size_t safe_backlog() const override { return core_.safe_pending(kBulkPriority); }
    std::optional<AirMeasure> air_measure() const override {
        const auto& st = core_.stats();
        return AirMeasure{st.air_carried, st.air_turnaround_ms};
    }

  private:
    void drain_events() {
        while (core_.poll_event()) {
        }
    }

    groundlink::Transport core_;
};

}  // namespace

std::unique_ptr<BenchEndpoint> make_transport_endpoint(const EndpointSetup& setup) {
    return std::make_unique<TransportBenchEndpoint>(setup);
}

}  // namespace airseg::linkbench
