#include "bench/linkbench/endpoint.hpp"
#include "bench/linkbench/seed_protocol.hpp"

namespace airseg::linkbench {

namespace {

// The seed writes every frame to its transmit port (the only port in single mode, addressTx in serialduo) and
// reads one receive stream.
class SeedBenchEndpoint final : public BenchEndpoint {
  public:
    explicit SeedBenchEndpoint(const EndpointSetup& setup)
        : tx_path_(setup.mode == LinkMode::Dual && !setup.is_a ? 1 : 0) {}

    bool send_safe(std::span<const std::uint8_t> msg, TimePoint now) override {
        return seed_.send_safe(msg, now);
    }
    // The seed has one Safe queue: commands wait behind whatever is queued.
    bool send_urgent(std::span<const std::uint8_t> msg, TimePoint now) override {
        return seed_.send_safe(msg, now);
    }
    void send_fast(std::uint16_t /*stream*/, std::span<const std::uint8_t> msg, TimePoint now) override {
        seed_.send_fast(msg, now);
    }
    void handle_bytes(std::size_t /*path*/, std::span<const std::uint8_t> bytes, TimePoint now) override {
        seed_.handle_bytes(bytes, now);
    }
    void handle_timeout(TimePoint now) override { seed_.handle_timeout(now); }
    std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now) override {
        if (path != tx_path_) {
            return std::nullopt;
        }
        return seed_.poll_transmit(now);
    }
    std::optional<BenchMessage> poll_message() override {
        auto m = seed_.poll_message();
        if (!m) {
            return std::nullopt;
        }
        return BenchMessage{m->safe, std::move(m->bytes)};
    }
    TimePoint poll_timeout() const override { return seed_.poll_timeout(); }
    std::size_t safe_backlog() const override { return seed_.safe_pending(); }
    bool request_ids() const override { return false; }

  private:
    seed::SeedEndpoint seed_;
    std::size_t tx_path_;
};

}  // namespace

std::unique_ptr<BenchEndpoint> make_seed_endpoint(const EndpointSetup& setup) {
    return std::make_unique<SeedBenchEndpoint>(setup);
}

}  // namespace airseg::linkbench
