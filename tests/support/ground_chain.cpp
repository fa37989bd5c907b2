#include "tests/support/ground_chain.hpp"

#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

namespace airseg::test {

namespace {
constexpr auto kGenerous = 60s;
}

GroundChain::GroundChain(std::string dir, std::vector<std::string> hub_args)
    : dir_(std::move(dir)), hub_args_(std::move(hub_args)), key_(file("control.key")) {
    std::filesystem::create_directories(dir_);
}

GroundChain::~GroundChain() {
    for (auto* p : {hub.get(), daemon.get()}) {
        if (p != nullptr && p->running()) {
            p->signal(SIGTERM);
            p->wait_exit(10s);
        }
    }
}

std::string GroundChain::start() {
    write_file(key_, std::string(64, 'c') + "\n");
    ::chmod(key_.c_str(), 0600);
    const std::map<std::string, std::string> env;
    linksim = std::make_unique<Subprocess>(
        std::vector<std::string>{binary("tools/linksim/airseg-linksim"), "--a", file("air"), "--b",
                                 file("ground"), "--baud", "57600", "--seed", "7"},
        env, dir_);
    if (!wait_until([&] {
            return std::filesystem::exists(file("air")) && std::filesystem::exists(file("ground"));
        })) {
        return "linksim made no ptys:\n" + linksim->err();
    }
    sim = std::make_unique<Subprocess>(
        std::vector<std::string>{binary("tools/apmsim/airseg-apmsim"), "--link", file("ttyACM0"), "--home",
                                 std::to_string(kHomeLat) + "," + std::to_string(kHomeLon), "--boot-delay",
                                 "0.5", "--calib-time", "0.5", "--speedup", "4", "--quiet"},
        env, dir_);
    if (!wait_until([&] { return std::filesystem::exists(file("ttyACM0")); })) {
        return "apmsim made no pty:\n" + sim->err();
    }
    daemon = std::make_unique<Subprocess>(
        std::vector<std::string>{
            binary("daemon/airsegd"), "--config", source_path("config/airseg.yaml"), "--set",
            "status.socket=" + file("status.sock"), "--set", "state_dir=" + file("state"), "--set",
            "autopilot.port=" + file("ttyACM0"), "--set", "groundlink.ports=[" + file("air") + "]", "--set",
            "groundlink.key_file=" + key_, "--set", "groundlink.mavlink_forward.enabled=true"},
        env, dir_);
    std::vector<std::string> argv{
        binary("ground/airseg-ground"), "--link", file("ground"), "--key", key_, "--socket", socket()};
    argv.insert(argv.end(), hub_args_.begin(), hub_args_.end());
    hub = std::make_unique<Subprocess>(argv, env, dir_);
    if (!wait_until([&] { return std::filesystem::exists(socket()); })) {
        return "the hub made no socket:\n" + hub->err();
    }
    nlohmann::json doc;
    const bool ready = wait_until(
        [&] {
            auto r = ctl({"status"});
            doc = nlohmann::json::parse(r.out, nullptr, false);
            return r.exit_code == 0 && doc.is_object() &&
                   doc.value("autopilot", nlohmann::json::object()).value("ready", false);
        },
        kGenerous, 500ms);
    if (!ready) {
        return doc.dump() + "\nhub:\n" + hub->err() + "\ndaemon:\n" + daemon->err();
    }
    return {};
}

std::vector<std::string> GroundChain::ctl_argv(std::vector<std::string> args, bool with_key) const {
    std::vector<std::string> argv{
        binary("client/airsegctl"), "--ground-socket", socket(), "--timeout", "30000", "--json"};
    if (with_key) {
        argv.insert(argv.end(), {"--key", key_});
    }
    argv.insert(argv.end(), args.begin(), args.end());
    return argv;
}

RunResult GroundChain::ctl(std::vector<std::string> args, bool with_key) const {
    return run(ctl_argv(std::move(args), with_key), {}, 90s);
}

}  // namespace airseg::test
