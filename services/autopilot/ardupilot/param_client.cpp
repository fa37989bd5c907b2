#include "services/autopilot/ardupilot/param_client.hpp"

#include <algorithm>
#include <cmath>

#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::autopilot::ardupilot {

namespace mav = airseg::mavlink;

namespace {
constexpr std::uint8_t kParamTypeReal32 = 9;
constexpr std::uint16_t kUnsolicitedIndex = 65535;

std::string format_value(float v) {
    std::string s = std::to_string(v);
    while (s.size() > 1 && s.back() == '0') {
        s.pop_back();
    }
    if (!s.empty() && s.back() == '.') {
        s.pop_back();
    }
    return s;
}
}  // namespace

ParamClient::ParamClient(Outbox& outbox, std::uint8_t target_sysid, std::uint8_t target_compid,
                         ParamClientConfig config)
    : out_(outbox), target_sysid_(target_sysid), target_compid_(target_compid), config_(config) {}

std::uint32_t ParamClient::fetch_all(TimePoint now) {
    Op op;
    op.kind = ParamCompletion::Kind::FetchAll;
    return enqueue(std::move(op), now);
}

std::uint32_t ParamClient::get(const std::string& name, TimePoint now) {
    Op op;
    op.kind = ParamCompletion::Kind::Get;
    op.name = name;
    return enqueue(std::move(op), now);
}

std::uint32_t ParamClient::set(const std::string& name, float value, TimePoint now) {
    Op op;
    op.kind = ParamCompletion::Kind::Set;
    op.name = name;
    op.value = value;
    return enqueue(std::move(op), now);
}

std::uint32_t ParamClient::enqueue(Op op, TimePoint now) {
    op.id = next_id_++;
    if (op.kind != ParamCompletion::Kind::FetchAll && (op.name.empty() || op.name.size() > 16)) {
        done_.push_back({op.id, op.kind, RequestResult::Invalid, op.name, std::nullopt,
                         "parameter name must be 1..16 characters"});
        return op.id;
    }
    if (op.kind == ParamCompletion::Kind::Set && !std::isfinite(op.value)) {
        done_.push_back(
            {op.id, op.kind, RequestResult::Invalid, op.name, std::nullopt, "value is not finite"});
        return op.id;
    }
    if (ops_.size() >= kMaxQueued) {
        done_.push_back(
            {op.id, op.kind, RequestResult::Busy, op.name, std::nullopt, "too many parameter requests"});
        return op.id;
    }
    const std::uint32_t id = op.id;
    ops_.push_back(std::move(op));
    if (ops_.size() == 1) {
        start_front(now);
    }
    return id;
}

void ParamClient::cancel_all(const std::string& why) {
    for (auto& op : ops_) {
        done_.push_back({op.id, op.kind, RequestResult::Cancelled, op.name, std::nullopt, why});
    }
    ops_.clear();
}

void ParamClient::start_front(TimePoint now) {
    if (ops_.empty() || ops_.front().started) {
        return;
    }
    Op& op = ops_.front();
    op.started = true;
    if (op.kind == ParamCompletion::Kind::FetchAll) {
        op.give_up = now + config_.fetch_timeout;
        std::fill(have_index_.begin(), have_index_.end(), false);
        have_count_ = 0;
    }
    send_for(op, now);
}

void ParamClient::send_for(Op& op, TimePoint now) {
    switch (op.kind) {
        case ParamCompletion::Kind::FetchAll:
            if (announced_ == 0 || have_count_ == 0) {
                mav::ParamRequestList m;
                m.target_system = target_sysid_;
                m.target_component = target_compid_;
                out_.send(m);
            } else {
                request_missing(now);
            }
            break;
        case ParamCompletion::Kind::Get: {
            mav::ParamRequestRead m;
            m.target_system = target_sysid_;
            m.target_component = target_compid_;
            m.param_index = -1;
            mav::set_text(m.param_id, op.name);
            out_.send(m);
            break;
        }
        case ParamCompletion::Kind::Set: {
            mav::ParamSet m;
            m.target_system = target_sysid_;
            m.target_component = target_compid_;
            mav::set_text(m.param_id, op.name);
            m.param_value = op.value;
            const auto it = table_.find(op.name);
            m.param_type = it != table_.end() ? it->second.type : kParamTypeReal32;
            out_.send(m);
            break;
        }
    }
    op.deadline = std::min(now + config_.timeout, op.give_up);
}

void ParamClient::request_missing(TimePoint) {
    std::size_t sent = 0;
    for (std::size_t i = 0; i < have_index_.size() && sent < kReadsPerRound; ++i) {
        if (!have_index_[i]) {
            mav::ParamRequestRead m;
            m.target_system = target_sysid_;
            m.target_component = target_compid_;
            m.param_index = static_cast<std::int16_t>(i);
            out_.send(m);
            ++sent;
        }
    }
}

bool ParamClient::fetch_complete() const {
    return announced_ > 0 && have_count_ == announced_;
}

bool ParamClient::same_value(float a, float b, std::uint8_t type) {
    if (type != kParamTypeReal32 && type != 10 /* REAL64 */) {
        return std::lround(a) == std::lround(b);
    }
    return a == b || std::fabs(a - b) <= 1e-6f * std::max(1.0f, std::fabs(a));
}

void ParamClient::finish(RequestResult r, std::optional<float> value, std::string detail, TimePoint now) {
    Op op = std::move(ops_.front());
    ops_.pop_front();
    done_.push_back({op.id, op.kind, r, op.name, value, std::move(detail)});
    start_front(now);
}

bool ParamClient::handle_frame(const mav::Frame& f, TimePoint now) {
    if (f.sysid != target_sysid_ || f.msgid != mav::ParamValue::kId) {
        return false;
    }
    const auto v = mav::decode_payload<mav::ParamValue>(f.payload_view());
    const std::string name(mav::text_of(v.param_id));
    if (name.empty()) {
        return true;
    }
    if (!std::all_of(name.begin(), name.end(), [](char c) { return c > ' ' && c < 0x7f; })) {
        ++dropped_;  // ArduPilot's names are letters, digits and '_'; anything else is noise or hostile
        return true;
    }
    if (v.param_count > 0 && v.param_count <= kMaxParams && v.param_count != announced_) {
        // A new table (first fetch, or firmware changed): start counting again; names of the old table go.
        if (announced_ != 0) {
            table_.clear();
        }
        announced_ = v.param_count;
        have_index_.assign(announced_, false);
        have_count_ = 0;
    }
    auto it = table_.find(name);
    if (it == table_.end() && table_.size() < (announced_ > 0 ? announced_ : kMaxParams)) {
        it = table_.emplace(name, ParamEntry{}).first;
    }
    const bool cached = it != table_.end();
    if (cached) {
        ParamEntry& entry = it->second;
        entry.value = v.param_value;
        entry.type = v.param_type;
        if (v.param_index != kUnsolicitedIndex) {
            entry.index = v.param_index;
        }
    } else {
        ++dropped_;  // more names than the table announced: not a parameter of this table
    }
    // A name that did not fit counts for no index: its index belongs to a name the table does hold.
    bool new_index = false;
    if (cached && v.param_index < have_index_.size() && !have_index_[v.param_index]) {
        have_index_[v.param_index] = true;
        ++have_count_;
        new_index = true;
    }
    if (ops_.empty() || !ops_.front().started) {
        return true;
    }
    Op& op = ops_.front();
    switch (op.kind) {
        case ParamCompletion::Kind::FetchAll:
            if (fetch_complete()) {
                finish(RequestResult::Ok, std::nullopt, {}, now);
            } else if (new_index) {
                op.attempt = 0;
                op.deadline = std::min(now + config_.timeout, op.give_up);
            }
            break;
        case ParamCompletion::Kind::Get:
            if (name == op.name) {
                finish(RequestResult::Ok, v.param_value, {}, now);
            }
            break;
        case ParamCompletion::Kind::Set:
            if (name != op.name) {
                break;
            }
            if (same_value(op.value, v.param_value, v.param_type)) {
                finish(RequestResult::Ok, v.param_value, {}, now);
                break;
            }
            // The echo disagrees: a stale value crossing our write, or the autopilot changed what we wrote.
            op.last_echo = v.param_value;
            if (op.attempt >= config_.retries) {
                finish(RequestResult::Refused, v.param_value,
                       op.name + ": wrote " + format_value(op.value) + ", autopilot reports " +
                           format_value(v.param_value),
                       now);
            } else {
                ++op.attempt;
                ++retransmissions_;
                send_for(op, now);
            }
            break;
    }
    return true;
}

void ParamClient::handle_timeout(TimePoint now) {
    if (ops_.empty() || now < ops_.front().deadline) {
        return;
    }
    Op& op = ops_.front();
    if (op.kind == ParamCompletion::Kind::FetchAll && now >= op.give_up) {
        finish(RequestResult::Timeout, std::nullopt,
               "parameter download: " + std::to_string(have_count_) + " of " + std::to_string(announced_) +
                   " received before the deadline",
               now);
        return;
    }
    if (op.attempt >= config_.retries) {
        if (op.kind == ParamCompletion::Kind::FetchAll) {
            finish(RequestResult::Timeout, std::nullopt,
                   "parameter download stalled at " + std::to_string(have_count_) + " of " +
                       std::to_string(announced_),
                   now);
        } else if (op.last_echo) {
            finish(RequestResult::Refused, op.last_echo,
                   op.name + ": wrote " + format_value(op.value) + ", autopilot reports " +
                       format_value(*op.last_echo),
                   now);
        } else {
            finish(RequestResult::Timeout, std::nullopt,
                   op.name + ": no answer after " + std::to_string(op.attempt + 1) + " attempts", now);
        }
        return;
    }
    ++op.attempt;
    ++retransmissions_;
    send_for(op, now);
}

TimePoint ParamClient::poll_timeout() const {
    return ops_.empty() ? kNever : ops_.front().deadline;
}

std::optional<ParamCompletion> ParamClient::poll_completion() {
    if (done_.empty()) {
        return std::nullopt;
    }
    auto c = std::move(done_.front());
    done_.pop_front();
    return c;
}

std::optional<float> ParamClient::cached(const std::string& name) const {
    const auto it = table_.find(name);
    if (it == table_.end()) {
        return std::nullopt;
    }
    return it->second.value;
}

}  // namespace airseg::autopilot::ardupilot
