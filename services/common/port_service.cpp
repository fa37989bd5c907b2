#include "services/common/port_service.hpp"

namespace airseg {

PortService::PortService(std::string name, ServiceContext& ctx, std::vector<PortKeeperConfig> ports)
    : Service(std::move(name), ctx) {
    for (auto& config : ports) {
        keepers_.push_back(std::make_unique<PortKeeper>(
            strand(), std::move(config),
            PortKeeper::Handlers{
                [this] { update_health(); }, {}, [this](const std::string&) { update_health(); }}));
    }
}

bool PortService::all_open() const {
    for (const auto& k : keepers_) {
        if (!k->is_open()) {
            return false;
        }
    }
    return true;
}

void PortService::on_start() {
    for (auto& k : keepers_) {
        k->start();
    }
    update_health();
}

void PortService::on_stop() {
    for (auto& k : keepers_) {
        k->stop();
    }
}

void PortService::update_health() {
    std::string reasons;
    std::size_t open = 0;
    for (const auto& k : keepers_) {
        if (k->is_open()) {
            ++open;
        } else {
            if (!reasons.empty()) {
                reasons += ", ";
            }
            reasons += k->last_error().empty() ? "opening" : k->last_error();
        }
    }
    // With two radios, one of them still carries the link: degraded, not down.
    const Health health = open == keepers_.size() ? Health::Up : open > 0 ? Health::Degraded : Health::Down;
    set_health(health, reasons);
}

}  // namespace airseg
