#include "services/flightplan/persistence.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <sstream>

#include "base/file_text.hpp"

namespace airseg::flightplan {

namespace {

constexpr std::string_view kPlanMagic = "# airseg-plan v1 ";
constexpr std::string_view kProgressMagic = "airseg-progress 1";

std::string errno_text(const char* what, const std::filesystem::path& path) {
    return std::string(what) + " " + path.string() + ": " + std::strerror(errno);
}

bool parse_u64(std::string_view s, std::uint64_t& out, int base = 10) {
    if (s.empty()) {
        return false;
    }
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out, base);
    return ec == std::errc{} && ptr == s.data() + s.size();
}

const char* state_name(PlanState s) {
    return to_string(s);
}

std::optional<PlanState> parse_state(std::string_view s) {
    for (auto st : {PlanState::None, PlanState::Running, PlanState::Paused, PlanState::Done,
                    PlanState::Interrupted, PlanState::Failed}) {
        if (s == to_string(st)) {
            return st;
        }
    }
    return std::nullopt;
}

std::string progress_body(const SavedProgress& p) {
    std::ostringstream o;
    o << kProgressMagic << '\n';
    o << "plan_digest " << p.plan_digest << '\n';
    o << "state " << state_name(p.state) << '\n';
    if (p.origin.element == StreamOrigin::kStreamStart) {
        o << "origin_element start\n";
    } else {
        o << "origin_element " << p.origin.element << '\n';
    }
    o << "origin_index " << p.origin.index << '\n';
    o << "next_index " << p.next_index << '\n';
    o << "waypoints_reached " << p.waypoints_reached << '\n';
    return o.str();
}

/// Strict parser: the exact keys in the exact order, then the checksum line. Anything else is corrupt.
std::optional<SavedProgress> parse_progress(std::string_view data, std::string& why) {
    const auto check_pos = data.rfind("check ");
    if (check_pos == std::string_view::npos || (check_pos > 0 && data[check_pos - 1] != '\n')) {
        why = "no checksum line (truncated?)";
        return std::nullopt;
    }
    const std::string_view body = data.substr(0, check_pos);
    std::string_view check = data.substr(check_pos + 6);
    if (!check.empty() && check.back() == '\n') {
        check.remove_suffix(1);
    }
    std::uint64_t expected = 0;
    if (!parse_u64(check, expected, 16) || expected != fnv1a64(body)) {
        why = "checksum mismatch";
        return std::nullopt;
    }
    std::vector<std::string_view> lines;
    for (std::size_t pos = 0; pos < body.size();) {
        const auto nl = body.find('\n', pos);
        if (nl == std::string_view::npos) {
            break;
        }
        lines.push_back(body.substr(pos, nl - pos));
        pos = nl + 1;
    }
    const char* keys[] = {"plan_digest",  "state",      "origin_element",
                          "origin_index", "next_index", "waypoints_reached"};
    if (lines.size() != 7 || lines[0] != kProgressMagic) {
        why = "unexpected layout";
        return std::nullopt;
    }
    std::string_view values[6];
    for (std::size_t i = 0; i < 6; ++i) {
        const std::string_view line = lines[i + 1];
        const std::string_view key = keys[i];
        if (line.size() <= key.size() || line.substr(0, key.size()) != key || line[key.size()] != ' ') {
            why = std::string("expected key ") + keys[i];
            return std::nullopt;
        }
        values[i] = line.substr(key.size() + 1);
    }
    SavedProgress p;
    p.plan_digest = std::string(values[0]);
    const auto state = parse_state(values[1]);
    std::uint64_t element = 0;
    const bool element_ok = values[2] == "start" || (parse_u64(values[2], element) && element < 0xFFFFFFFFu);
    if (!state || !element_ok || !parse_u64(values[3], p.origin.index) ||
        !parse_u64(values[4], p.next_index) || !parse_u64(values[5], p.waypoints_reached) ||
        p.next_index < p.origin.index) {
        why = "bad value";
        return std::nullopt;
    }
    p.state = *state;
    p.origin.element =
        values[2] == "start" ? StreamOrigin::kStreamStart : static_cast<std::uint32_t>(element);
    return p;
}

}  // namespace

std::string hex64(std::uint64_t v) {
    char buf[17];
    auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v, 16);
    return std::string(16 - static_cast<std::size_t>(ptr - buf), '0') + std::string(buf, ptr);
}

SavedProgress SavedProgress::from(const FeederProgress& progress, std::string plan_digest) {
    SavedProgress p;
    p.plan_digest = std::move(plan_digest);
    p.state = progress.state;
    p.origin = progress.resume_origin;
    p.next_index = progress.resume_index.value_or(progress.resume_origin.index);
    p.waypoints_reached = progress.waypoints_reached;
    return p;
}

std::optional<std::string> write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                                                 Durability durability) {
    const std::filesystem::path tmp = path.string() + ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        return errno_text("cannot create", tmp);
    }
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            auto err = errno_text("cannot write", tmp);
            ::close(fd);
            ::unlink(tmp.c_str());
            return err;
        }
        done += static_cast<std::size_t>(n);
    }
    if (durability == Durability::Fsync && ::fsync(fd) != 0) {
        auto err = errno_text("cannot fsync", tmp);
        ::close(fd);
        ::unlink(tmp.c_str());
        return err;
    }
    if (::close(fd) != 0) {
        return errno_text("cannot close", tmp);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        auto err = errno_text("cannot rename to", path);
        ::unlink(tmp.c_str());
        return err;
    }
    // Make the rename itself durable.
    const std::filesystem::path dir =
        path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    const int dfd =
        durability == Durability::Fsync ? ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC) : -1;
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
    return std::nullopt;
}

StateStore::StateStore(std::filesystem::path directory, Durability durability)
    : dir_(std::move(directory)), durability_(durability) {}

std::optional<std::string> StateStore::save_plan(std::string_view text, std::string_view source_name) {
    if (text.size() > kMaxPlanBytes) {
        return "plan too large to store";
    }
    std::string source(source_name);
    for (char& c : source) {
        if (c == '\n' || c == '\r') {
            c = ' ';
        }
    }
    std::string out = std::string(kPlanMagic) + "fnv64=" + hex64(fnv1a64(text)) +
                      " bytes=" + std::to_string(text.size()) + " source=" + source + "\n";
    out += text;
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    return write_file_atomically(plan_path(), out, durability_);
}

std::optional<std::string> StateStore::save_progress(const SavedProgress& progress) {
    std::string body = progress_body(progress);
    body += "check " + hex64(fnv1a64(body)) + "\n";
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    return write_file_atomically(progress_path(), body, durability_);
}

std::optional<std::string> StateStore::clear() {
    std::error_code ec;
    std::filesystem::remove(progress_path(), ec);
    if (ec) {
        return "cannot remove " + progress_path().string() + ": " + ec.message();
    }
    std::filesystem::remove(plan_path(), ec);
    if (ec) {
        return "cannot remove " + plan_path().string() + ": " + ec.message();
    }
    return std::nullopt;
}

std::optional<std::string> StateStore::set_aside(const std::filesystem::path& path) {
    std::error_code ec;
    for (int n = 1; n < 10000; ++n) {
        const std::filesystem::path target = path.string() + ".corrupt-" + std::to_string(n);
        if (std::filesystem::exists(target, ec)) {
            continue;
        }
        std::filesystem::rename(path, target, ec);
        if (ec) {
            return "cannot set aside " + path.string() + ": " + ec.message();
        }
        return std::nullopt;
    }
    return "too many corrupt copies of " + path.string();
}

std::vector<std::string> StateStore::set_aside_plan() {
    std::vector<std::string> problems;
    std::error_code ec;
    for (const auto& p : {plan_path(), progress_path()}) {
        if (std::filesystem::exists(std::filesystem::symlink_status(p, ec))) {
            if (auto err = set_aside(p)) {
                problems.push_back(std::move(*err));
            }
        }
    }
    return problems;
}

StoredState StateStore::load() {
    StoredState out;
    std::error_code ec;
    // Leftovers of a write interrupted before its rename: never the current state.
    for (const auto& p : {plan_path(), progress_path()}) {
        std::filesystem::remove(p.string() + ".tmp", ec);
    }

    std::string digest;
    if (std::filesystem::exists(plan_path(), ec)) {
        std::string why;
        auto file = read_file_text(plan_path().string(), kMaxPlanFileBytes);
        const std::string* data = &file.text;
        if (!file.ok()) {
            why = file.error;
        } else if (data->compare(0, kPlanMagic.size(), kPlanMagic) != 0) {
            why = "missing header";
        } else {
            const auto nl = data->find('\n');
            const std::string_view header =
                std::string_view(*data).substr(0, nl == std::string::npos ? 0 : nl);
            const std::string_view text =
                nl == std::string::npos ? std::string_view{} : std::string_view(*data).substr(nl + 1);
            const auto f = header.find("fnv64="), b = header.find(" bytes="), s = header.find(" source=");
            std::uint64_t sum = 0, bytes = 0;
            if (nl == std::string::npos || f == std::string_view::npos || b == std::string_view::npos ||
                s == std::string_view::npos || b < f || s < b ||
                !parse_u64(header.substr(f + 6, b - f - 6), sum, 16) ||
                !parse_u64(header.substr(b + 7, s - b - 7), bytes)) {
                why = "malformed header";
            } else if (bytes != text.size() || sum != fnv1a64(text)) {
                why = "checksum mismatch (truncated or altered)";
            } else {
                out.plan_text = std::string(text);
                out.plan_source = std::string(header.substr(s + 8));
                digest = hex64(sum);
            }
        }
        if (!out.plan_text) {
            out.problems.push_back(plan_path().string() + ": " + why + "; set aside");
            if (auto err = set_aside(plan_path())) {
                out.problems.push_back(*err);
            }
        }
    }

    if (std::filesystem::exists(progress_path(), ec)) {
        std::string why;
        std::optional<SavedProgress> p;
        auto file = read_file_text(progress_path().string(), kMaxProgressBytes);
        const std::string* data = &file.text;
        if (!file.ok()) {
            why = file.error;
        } else {
            p = parse_progress(*data, why);
            if (p && p->plan_digest != digest) {
                why = out.plan_text ? "belongs to another plan" : "no valid plan to go with it";
                p.reset();
            }
        }
        if (p) {
            out.progress = p;
        } else {
            out.problems.push_back(progress_path().string() + ": " + why + "; set aside");
            if (auto err = set_aside(progress_path())) {
                out.problems.push_back(*err);
            }
        }
    }
    return out;
}

}  // namespace airseg::flightplan
