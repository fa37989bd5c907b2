#include "services/common/health.hpp"

namespace airseg {

const char* to_string(Health h) {
    switch (h) {
        case Health::Up:
            return "up";
        case Health::Degraded:
            return "degraded";
        case Health::Down:
            return "down";
    }
    return "down";
}

void HealthRegistry::add(const std::string& name, TimePoint now, std::string reason) {
    std::lock_guard lock(mutex_);
    auto& entry = services_[name];
    entry.name = name;
    entry.health = Health::Down;
    entry.error = std::move(reason);
    entry.since = std::chrono::system_clock::now();
    entry.last_progress = now;
}

bool HealthRegistry::set(const std::string& name, Health health, std::string error) {
    std::lock_guard lock(mutex_);
    auto it = services_.find(name);
    if (it == services_.end()) {
        return false;
    }
    auto& entry = it->second;
    if (entry.health == health && entry.error == error) {
        return false;
    }
    if (entry.health != health) {
        entry.since = std::chrono::system_clock::now();
    }
    entry.health = health;
    entry.error = std::move(error);
    return true;
}

void HealthRegistry::progress(const std::string& name, TimePoint now) {
    std::lock_guard lock(mutex_);
    auto it = services_.find(name);
    if (it != services_.end() && now > it->second.last_progress) {
        it->second.last_progress = now;
    }
}

std::vector<ServiceHealth> HealthRegistry::snapshot() const {
    std::lock_guard lock(mutex_);
    std::vector<ServiceHealth> out;
    out.reserve(services_.size());
    for (const auto& [name, entry] : services_) {
        out.push_back(entry);
    }
    return out;
}

std::vector<std::string> HealthRegistry::stalled(TimePoint now, Duration period) const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [name, entry] : services_) {
        if (now - entry.last_progress > period) {
            out.push_back(name);
        }
    }
    return out;
}

}  // namespace airseg
