// MapServer on real sockets (an ephemeral port): routes, refusals, the event stream, commands, kept-alive and
// pipelined requests, and the bounds that keep the page served.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include "ground/map/beast.hpp"
#include "ground/map/map_server.hpp"
#include "ground/map/plan_export.hpp"

namespace airseg::ground {
namespace {

using Json = nlohmann::json;
using asio::ip::tcp;

/// One browser connection, reading answers as a browser does: one whole response at a time (Beast's parser),
/// so that a kept-alive connection needs no close to end an answer.
struct Client {
    explicit Client(std::uint16_t port) {
        socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    }

    void send(const std::string& raw) { asio::write(socket, asio::buffer(raw)); }

    /// The next response as text (head and body); empty when the connection ended instead.
    std::string response(bool to_head = false) {
        beast_http::response_parser<beast_http::string_body> parser;
        parser.skip(to_head);
        parser.body_limit(64u << 20);
        beast::error_code ec;
        beast_http::read(socket, buffer, parser, ec);
        if (ec) {
            return {};
        }
        std::ostringstream text;
        text << parser.get();
        return text.str();
    }

    /// Whether the server ends the connection (rather than sending anything more).
    bool ended_by_server() {
        std::array<char, 256> chunk{};
        boost::system::error_code ec;
        const auto n = socket.read_some(asio::buffer(chunk), ec);
        return n == 0 && ec;
    }

    asio::io_context io;
    tcp::socket socket{io};
    beast::flat_buffer buffer;
};

/// A MapServer on its own io_context thread; calls into it go through its strand.
struct Rig {
    explicit Rig(MapConfig config = {}, bool start_it = true) {
        leaflet = std::filesystem::temp_directory_path() /
                  ("airseg-map-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        std::filesystem::create_directories(leaflet);
        std::ofstream(leaflet / "leaflet.css") << "/* leaflet */";
        config.listen = config.listen == MapConfig{}.listen ? "127.0.0.1:0" : config.listen;
        config.leaflet_dir = leaflet.string();
        map =
            std::make_unique<MapServer>(strand, config, [this](Json request, std::function<void(Json)> done) {
                commands.push_back(request);
                done({{"ok", true}, {"result", {{"state", "paused"}}}});
            });
        if (start_it) {
            EXPECT_EQ(map->start(), "");
        }
        thread = std::thread([this] { io.run(); });
    }
    ~Rig() {
        on_strand([this] { map->stop(); });
        work = asio::any_io_executor();
        thread.join();
        map.reset();
        std::filesystem::remove_all(leaflet);
    }

    template <typename F>
    void on_strand(F f) {
        std::promise<void> done;
        asio::post(strand, [&] {
            f();
            done.set_value();
        });
        done.get_future().wait();
    }

    /// Sends `raw` on a new connection and reads its answer.
    std::string exchange(const std::string& raw) const {
        Client client(map->port());
        client.send(raw);
        return client.response(raw.starts_with("HEAD "));
    }

    std::string get(const std::string& path) const {
        return exchange("GET " + path + " HTTP/1.1\r\nHost: localhost\r\n\r\n");
    }

    /// The page's token, read as the page reads it: from the first (state) event of /events.
    std::string page_token() const {
        asio::io_context client;
        tcp::socket s(client);
        s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), map->port()));
        asio::write(s, asio::buffer(std::string("GET /events HTTP/1.1\r\nHost: localhost\r\n\r\n")));
        std::string buffer;
        for (;;) {
            const auto data = buffer.find("data: ");
            const auto end = data == std::string::npos ? data : buffer.find("\n\n", data);
            if (end != std::string::npos) {
                return Json::parse(buffer.substr(data + 6, end - data - 6)).value("token", "");
            }
            std::array<char, 4096> chunk{};
            buffer.append(chunk.data(), s.read_some(asio::buffer(chunk)));
        }
    }

    /// A command as the map's own page sends it (its origin and token), unless `headers` says otherwise.
    std::string post_command(const std::string& body,
                             std::optional<std::string> headers = std::nullopt) const {
        if (!headers) {
            headers = "Origin: http://localhost\r\nX-Airseg-Token: " + page_token() + "\r\n";
        }
        return exchange(
            "POST /api/command HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n" + *headers +
            "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body);
    }

    static inline int counter = 0;
    asio::io_context io;
    asio::strand<asio::io_context::executor_type> strand = asio::make_strand(io);
    // Keeps run() going while no socket waits (until the destructor lets it end).
    asio::any_io_executor work = asio::prefer(io.get_executor(), asio::execution::outstanding_work.tracked);
    std::filesystem::path leaflet;
    std::unique_ptr<MapServer> map;
    std::vector<Json> commands;  // touched on the strand only
    std::thread thread;
};

std::string status_line(const std::string& response) {
    return response.substr(0, response.find("\r\n"));
}

std::string body_of(const std::string& response) {
    const auto at = response.find("\r\n\r\n");
    return at == std::string::npos ? std::string() : response.substr(at + 4);
}

TEST(MapServer, ServesThePageLeafletAndTheExports) {
    Rig rig;
    const auto page = rig.get("/");
    EXPECT_EQ(status_line(page), "HTTP/1.1 200 OK");
    EXPECT_NE(page.find("Content-Type: text/html"), std::string::npos);
    EXPECT_NE(page.find("/static/map.js"), std::string::npos);
    EXPECT_EQ(status_line(rig.get("/static/map.js")), "HTTP/1.1 200 OK");
    const auto css = rig.get("/leaflet/leaflet.css");
    EXPECT_EQ(status_line(css), "HTTP/1.1 200 OK");
    EXPECT_EQ(body_of(css), "/* leaflet */");
    EXPECT_NE(css.find("Content-Type: text/css"), std::string::npos);

    rig.on_strand([&] {
        rig.map->set_plan(Json::parse(R"({"name":"p","elements":[
        {"path":"plan.elements[0]","kind":"waypoint","name":null,"closed":false,"points":[[41,2],[41.1,2]]}],
        "no_fly":[]})"));
    });
    const auto geojson = rig.get("/plan.geojson");
    EXPECT_NE(geojson.find("Content-Type: application/geo+json"), std::string::npos);
    EXPECT_EQ(Json::parse(body_of(geojson))["features"].size(), 1u);
    EXPECT_NE(rig.get("/plan.kml").find("Content-Type: application/vnd.google-earth.kml+xml"),
              std::string::npos);
    EXPECT_EQ(Json::parse(body_of(rig.get("/track.geojson")))["type"], "FeatureCollection");
    EXPECT_NE(body_of(rig.get("/track.kml")).find("<kml"), std::string::npos);
    const auto head = rig.exchange("HEAD / HTTP/1.1\r\nHost: localhost\r\n\r\n");
    EXPECT_EQ(status_line(head), "HTTP/1.1 200 OK");
    EXPECT_EQ(body_of(head), "");
}

TEST(MapServer, UnknownPathsEscapesAndBadRequestsAreRefused) {
    Rig rig;
    EXPECT_EQ(status_line(rig.get("/nothing")), "HTTP/1.1 404 Not Found");
    EXPECT_EQ(status_line(rig.get("/leaflet/../../etc/passwd")), "HTTP/1.1 404 Not Found");
    EXPECT_EQ(status_line(rig.get("/leaflet/%2e%2e/%2e%2e/etc/passwd")), "HTTP/1.1 404 Not Found");
    EXPECT_EQ(status_line(rig.get("/static/")), "HTTP/1.1 404 Not Found");
    const auto bad = rig.exchange("NONSENSE\r\n\r\n");
    EXPECT_EQ(status_line(bad), "HTTP/1.1 400 Bad Request");
    EXPECT_NE(body_of(bad).find("request line"), std::string::npos) << "the reason is given";
    EXPECT_EQ(status_line(rig.exchange("GET / HTTP/1.1\r\n\r\n")), "HTTP/1.1 400 Bad Request");
    const auto huge =
        rig.exchange("POST /api/command HTTP/1.1\r\nHost: localhost\r\nContent-Length: 999999999\r\n\r\n");
    EXPECT_EQ(status_line(huge), "HTTP/1.1 413 Content Too Large");
    const auto wrong = rig.exchange("DELETE / HTTP/1.1\r\nHost: localhost\r\n\r\n");
    EXPECT_EQ(status_line(wrong), "HTTP/1.1 405 Method Not Allowed");
    EXPECT_EQ(status_line(rig.get("/api/command")), "HTTP/1.1 405 Method Not Allowed");
}

TEST(MapServer, CommandsAreRefusedWithoutControl) {
    Rig rig;
    const auto r = rig.post_command(R"({"cmd":"plan.pause"})");
    EXPECT_EQ(status_line(r), "HTTP/1.1 403 Forbidden");
    EXPECT_NE(Json::parse(body_of(r))["error"].get<std::string>().find("without control"), std::string::npos);
    rig.on_strand([&] { EXPECT_TRUE(rig.commands.empty()); });
}

TEST(MapServer, WithControlOnlyPlanCommandsReachTheVehicle) {
    MapConfig config;
    config.control = true;
    Rig rig(config);
    const auto r = rig.post_command(R"({"cmd":"plan.pause","extra":1})");
    EXPECT_EQ(status_line(r), "HTTP/1.1 200 OK");
    EXPECT_EQ(Json::parse(body_of(r))["result"]["state"], "paused");
    EXPECT_EQ(status_line(rig.post_command(R"({"cmd":"plan.skip","element":"gate"})")), "HTTP/1.1 200 OK");
    EXPECT_EQ(status_line(rig.post_command(R"({"cmd":"plan.load","text":"plan: {}","source":"f.yaml"})")),
              "HTTP/1.1 200 OK");
    const auto refused = rig.post_command(R"({"cmd":"param.set","name":"X"})");
    EXPECT_EQ(status_line(refused), "HTTP/1.1 400 Bad Request");
    EXPECT_NE(body_of(refused).find("not a map command"), std::string::npos);
    EXPECT_EQ(status_line(rig.post_command(R"({"cmd":"plan.load","path":"/etc/passwd"})")),
              "HTTP/1.1 400 Bad Request");
    EXPECT_EQ(status_line(rig.post_command("not json")), "HTTP/1.1 400 Bad Request");
    EXPECT_EQ(status_line(rig.post_command(R"({"cmd":"plan.skip"})")), "HTTP/1.1 400 Bad Request");
    rig.on_strand([&] {
        ASSERT_EQ(rig.commands.size(), 3u);
        EXPECT_EQ(rig.commands[0], Json::parse(R"({"cmd":"plan.pause"})")) << "only the command's own fields";
        EXPECT_EQ(rig.commands[1], Json::parse(R"({"cmd":"plan.skip","element":"gate"})"));
        EXPECT_EQ(rig.commands[2], Json::parse(R"({"cmd":"plan.load","text":"plan: {}","source":"f.yaml"})"));
    });
}

// Any page the operator's browser opens can send requests to the map: one on another origin POSTs without
// reading the answer, one on a name rebound to 127.0.0.1 reads the map as its own. Neither commands anything.
TEST(MapServer, CommandsNeedThePagesTokenAndOriginAndRequestsMustNameTheMap) {
    MapConfig config;
    config.control = true;
    config.host_names = {"Rover-Base.local"};
    Rig rig(config);
    const auto token = rig.page_token();
    EXPECT_EQ(token.size(), 32u);
    const std::string body = R"({"cmd":"plan.pause"})";
    const auto no_token = rig.post_command(body, "");
    EXPECT_EQ(status_line(no_token), "HTTP/1.1 403 Forbidden");
    EXPECT_NE(body_of(no_token).find("not from this map's page"), std::string::npos) << no_token;
    EXPECT_EQ(status_line(rig.post_command(body, "X-Airseg-Token: " + std::string(32, '0') + "\r\n")),
              "HTTP/1.1 403 Forbidden");
    const auto foreign =
        rig.post_command(body, "Origin: http://evil.example\r\nX-Airseg-Token: " + token + "\r\n");
    EXPECT_EQ(status_line(foreign), "HTTP/1.1 403 Forbidden");
    EXPECT_NE(body_of(foreign).find("a page from http://evil.example may not command"), std::string::npos)
        << foreign;
    // A tool without an Origin (curl) with the token is the page's equal.
    EXPECT_EQ(status_line(rig.post_command(body, "X-Airseg-Token: " + token + "\r\n")), "HTTP/1.1 200 OK");
    rig.on_strand([&] { EXPECT_EQ(rig.commands.size(), 1u); });

    const auto as_host = [&](const std::string& host) {
        return status_line(rig.exchange("GET / HTTP/1.1\r\nHost: " + host + "\r\n\r\n"));
    };
    EXPECT_EQ(as_host("evil.example:8080"), "HTTP/1.1 403 Forbidden") << "DNS rebinding";
    EXPECT_EQ(as_host("localhost.evil.example"), "HTTP/1.1 403 Forbidden");
    EXPECT_EQ(as_host("127.0.0.1:9000"), "HTTP/1.1 200 OK") << "an address, on any port (an SSH tunnel)";
    EXPECT_EQ(as_host("[::1]:8080"), "HTTP/1.1 200 OK");
    EXPECT_EQ(as_host("LOCALHOST"), "HTTP/1.1 200 OK");
    EXPECT_EQ(as_host("rover-base.LOCAL:8080"), "HTTP/1.1 200 OK") << "a configured name";
    EXPECT_EQ(as_host("[::1"), "HTTP/1.1 403 Forbidden");
}

TEST(MapServer, AViewOnlyMapGivesNoToken) {
    Rig rig;
    EXPECT_EQ(rig.page_token(), "");
}

/// Reads server-sent events until `count` have arrived (after the response head).
std::vector<std::pair<std::string, Json>> read_events(tcp::socket& s, std::string& buffer,
                                                      std::size_t count) {
    std::vector<std::pair<std::string, Json>> out;
    while (out.size() < count) {
        const auto end = buffer.find("\n\n");
        if (end == std::string::npos) {
            std::array<char, 4096> chunk{};
            const auto n = s.read_some(asio::buffer(chunk));
            buffer.append(chunk.data(), n);
            continue;
        }
        const std::string block = buffer.substr(0, end);
        buffer.erase(0, end + 2);
        std::string event;
        std::string data;
        std::size_t at = 0;
        while (at < block.size()) {
            auto eol = block.find('\n', at);
            const std::string line =
                block.substr(at, eol == std::string::npos ? std::string::npos : eol - at);
            at = eol == std::string::npos ? block.size() : eol + 1;
            if (line.starts_with("event: ")) {
                event = line.substr(7);
            } else if (line.starts_with("data: ")) {
                data = line.substr(6);
            }
        }
        if (!event.empty()) {
            out.emplace_back(event, Json::parse(data));
        }
    }
    return out;
}

TEST(MapServer, TheEventStreamStartsWithTheWholeStateThenFollowsUpdates) {
    Rig rig;
    groundlink::protocol::Telemetry t;
    t.lat_deg = 41.5;
    t.lon_deg = 2.5;
    t.heading_deg = 90;
    rig.on_strand([&] {
        rig.map->set_plan(Json::parse(R"({"name":"p","elements":[],"no_fly":[]})"));
        rig.map->add_position(t, std::chrono::system_clock::now());
        rig.map->set_link({{"link", "up"}, {"rtt_ms", 50}});
        rig.map->add_event("hello");
    });
    asio::io_context client;
    tcp::socket s(client);
    s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), rig.map->port()));
    asio::write(s, asio::buffer(std::string(
                       "GET /events HTTP/1.1\r\nHost: localhost\r\nAccept: text/event-stream\r\n\r\n")));
    std::string buffer;
    asio::read_until(s, asio::dynamic_buffer(buffer), "\r\n\r\n");
    ASSERT_TRUE(buffer.starts_with("HTTP/1.1 200 OK\r\n"));
    ASSERT_NE(buffer.find("Content-Type: text/event-stream"), std::string::npos);
    buffer.erase(0, buffer.find("\r\n\r\n") + 4);

    auto first = read_events(s, buffer, 1);
    ASSERT_EQ(first[0].first, "state");
    const Json& state = first[0].second;
    EXPECT_EQ(state["plan"]["name"], "p");
    EXPECT_EQ(state["track"], Json::parse("[[41.5, 2.5]]"));
    EXPECT_EQ(state["position"]["heading"], 90.0);
    EXPECT_EQ(state["link"]["rtt_ms"], 50);
    EXPECT_EQ(state["events"][0]["text"], "hello");
    EXPECT_EQ(state["control"], false);

    // A sample without a valid position is no place: neither the vehicle nor its track moves, and the page
    // is told once that there is no fix (not again for the next such sample).
    groundlink::protocol::Telemetry nowhere;
    nowhere.no_position = true;
    nowhere.gps_fix = 1;
    t.lat_deg = 41.6;
    rig.on_strand([&] {
        rig.map->add_position(nowhere, std::chrono::system_clock::now());
        rig.map->add_position(nowhere, std::chrono::system_clock::now());
        rig.map->add_position(t, std::chrono::system_clock::now());
        rig.map->add_event("bad \xff utf-8 <b>");
    });
    const auto next = read_events(s, buffer, 3);
    EXPECT_EQ(next[0].first, "fix");
    EXPECT_EQ(next[0].second["valid"], false);
    EXPECT_EQ(next[0].second["gps_fix"], 1);
    EXPECT_EQ(next[1].first, "position");
    EXPECT_EQ(next[1].second["lat"], 41.6);
    EXPECT_EQ(next[2].first, "event");
    EXPECT_NE(next[2].second["text"].get<std::string>().find("<b>"), std::string::npos);
}

TEST(MapServer, ManyBrowsersAtOnceAreServed) {
    Rig rig;
    std::vector<std::future<std::string>> answers;
    for (int i = 0; i < 20; ++i) {
        answers.push_back(std::async(std::launch::async, [&] { return rig.get("/static/map.css"); }));
    }
    for (auto& a : answers) {
        EXPECT_EQ(status_line(a.get()), "HTTP/1.1 200 OK");
    }
}

// A browser keeps its connection open between requests: two requests, one connection, two answers.
TEST(MapServer, AKeptAliveConnectionServesOneRequestAfterAnother) {
    Rig rig;
    Client client(rig.map->port());
    client.send("GET / HTTP/1.1\r\nHost: localhost\r\n\r\n");
    const auto page = client.response();
    EXPECT_EQ(status_line(page), "HTTP/1.1 200 OK");
    EXPECT_EQ(page.find("Connection: close"), std::string::npos) << page.substr(0, 300);
    client.send("GET /leaflet/leaflet.css HTTP/1.1\r\nHost: localhost\r\n\r\n");
    const auto css = client.response();
    EXPECT_EQ(status_line(css), "HTTP/1.1 200 OK");
    EXPECT_EQ(body_of(css), "/* leaflet */");
    // Refusals that keep the request's boundaries keep the connection too.
    client.send("GET /nothing HTTP/1.1\r\nHost: localhost\r\n\r\n");
    EXPECT_EQ(status_line(client.response()), "HTTP/1.1 404 Not Found");
    client.send("GET /track.geojson HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
    const auto last = client.response();
    EXPECT_EQ(status_line(last), "HTTP/1.1 200 OK");
    EXPECT_NE(last.find("Connection: close"), std::string::npos) << "asked to close";
    EXPECT_TRUE(client.ended_by_server());
    MapServer::Counts counts;
    rig.on_strand([&] { counts = rig.map->counts(); });
    EXPECT_EQ(counts.accepted, 1u) << "one connection for the four requests";
}

// Requests pipelined in one write are answered one by one, in the order sent (a HEAD's answer has no body,
// which the next answer must not be mistaken for).
// A request that never finishes arriving gets 408 and its connection back; a kept-alive connection with
// nothing more to ask is closed without a word; a client that stops reading an answer loses its connection
// (deadlines shortened from 15 s and 30 s).
TEST(MapServer, SlowRequestsIdleConnectionsAndClientsThatStopReadingAreCutOff) {
    MapConfig config;
    config.request_deadline = std::chrono::milliseconds(300);
    config.answer_deadline = std::chrono::milliseconds(300);
    Rig rig(config);

    Client slow(rig.map->port());
    const auto started = std::chrono::steady_clock::now();
    slow.send("GET / HTTP/1.1\r\nHost: loc");  // and no more
    const auto timeout = slow.response();
    EXPECT_EQ(status_line(timeout), "HTTP/1.1 408 Request Timeout") << timeout.substr(0, 200);
    EXPECT_GE(std::chrono::steady_clock::now() - started, std::chrono::milliseconds(250));
    EXPECT_TRUE(slow.ended_by_server());

    Client idle(rig.map->port());
    idle.send("GET /leaflet/leaflet.css HTTP/1.1\r\nHost: localhost\r\n\r\n");
    EXPECT_EQ(status_line(idle.response()), "HTTP/1.1 200 OK");
    EXPECT_TRUE(idle.ended_by_server()) << "closed after the deadline, without an answer of its own";
    MapServer::Counts counts;
    rig.on_strand([&] { counts = rig.map->counts(); });
    EXPECT_EQ(counts.request_timeouts, 2u) << "the slow request and the idle kept-alive connection";

    // More than the loopback's socket buffers hold: the answer cannot be written while the client reads
    // nothing, and the server closes the connection before it all went.
    constexpr std::size_t kBig = 7u << 20;
    std::ofstream(rig.leaflet / "big.js") << std::string(kBig, 'x');
    Client stalled(rig.map->port());
    stalled.socket.set_option(asio::socket_base::receive_buffer_size(4096));
    stalled.send("GET /leaflet/big.js HTTP/1.1\r\nHost: localhost\r\n\r\n");
    const auto cut_off = [&] {
        MapServer::Counts now;
        rig.on_strand([&] { now = rig.map->counts(); });
        return now.answers_cut_off;
    };
    const auto limit = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (cut_off() == 0 && std::chrono::steady_clock::now() < limit) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(cut_off(), 1u) << "the stalled client's connection was not closed";
    // (What the kernel had already taken of the answer still trickles to the client after the close, through
    // its small window and the orphaned socket's persist timer: reading it to the end takes minutes.)
}

TEST(MapServer, PipelinedRequestsAreAnsweredInOrder) {
    Rig rig;
    Client client(rig.map->port());
    client.send(
        "HEAD / HTTP/1.1\r\nHost: localhost\r\n\r\n"
        "GET /leaflet/leaflet.css HTTP/1.1\r\nHost: localhost\r\n\r\n"
        "GET /nothing HTTP/1.1\r\nHost: localhost\r\n\r\n"
        "GET /track.geojson HTTP/1.1\r\nHost: localhost\r\n\r\n");
    const auto head = client.response(true);
    EXPECT_EQ(status_line(head), "HTTP/1.1 200 OK");
    EXPECT_NE(head.find("Content-Type: text/html"), std::string::npos);
    EXPECT_EQ(body_of(head), "");
    const auto css = client.response();
    EXPECT_EQ(status_line(css), "HTTP/1.1 200 OK");
    EXPECT_EQ(body_of(css), "/* leaflet */");
    const auto missing = client.response();
    EXPECT_EQ(status_line(missing), "HTTP/1.1 404 Not Found");
    EXPECT_NE(body_of(missing).find("/nothing"), std::string::npos);
    const auto track = client.response();
    EXPECT_EQ(status_line(track), "HTTP/1.1 200 OK");
    EXPECT_EQ(Json::parse(body_of(track))["type"], "FeatureCollection");

    // Two more in one write, the first a command: its body is its own, the second request is read after it.
    client.send(
        "POST /api/command HTTP/1.1\r\nHost: localhost\r\nContent-Length: 20\r\n\r\n{\"cmd\":\"plan.pause\"}"
        "GET /leaflet/leaflet.css HTTP/1.1\r\nHost: localhost\r\n\r\n");
    const auto refused = client.response();
    EXPECT_EQ(status_line(refused), "HTTP/1.1 403 Forbidden") << "a view-only map";
    EXPECT_EQ(body_of(client.response()), "/* leaflet */");
}

// Lines ended by a bare LF: Beast refuses them (400, with the reason) at once and the connection ends;
// nothing waits for a CRLF that never comes.
TEST(MapServer, ABareLfRequestIsRefusedAtOnce) {
    Rig rig;
    for (const std::string raw :
         {"GET / HTTP/1.1\nHost: localhost\n\n", "GET / HTTP/1.1\r\nHost: localhost\n\n"}) {
        Client client(rig.map->port());
        const auto asked = std::chrono::steady_clock::now();
        client.send(raw);
        const auto answer = client.response();
        const auto took = std::chrono::steady_clock::now() - asked;
        EXPECT_EQ(status_line(answer), "HTTP/1.1 400 Bad Request") << raw;
        EXPECT_NE(body_of(answer).find("CRLF"), std::string::npos) << answer;
        EXPECT_NE(answer.find("Connection: close"), std::string::npos);
        EXPECT_TRUE(client.ended_by_server());
        EXPECT_LT(took, std::chrono::seconds(5)) << "not the 15 s request deadline";
    }
}

/// Room for this test's own sockets and the server's, whatever the shell's default.
void raise_descriptor_limit(rlim_t wanted) {
    rlimit limit{};
    ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &limit), 0);
    if (limit.rlim_cur < wanted) {
        limit.rlim_cur = std::min(wanted, limit.rlim_max);
        ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &limit), 0);
    }
    ASSERT_GE(limit.rlim_cur, 1500u) << "too few descriptors for 600 connections, both ends";
}

// The acceptance case: 100 live maps asked for and 500 connections that never send a request (50 of them kept
// alive after a first request). The streams are bounded by their own limit (the 33rd is answered 503), idle
// connections give way to newcomers, and GET / on a new connection is answered within 1 s.
TEST(MapServer, IdleConnectionsAndManyLiveMapsCannotLockOutThePage) {
    raise_descriptor_limit(4096);
    Rig rig;
    asio::io_context client;
    const tcp::endpoint at(asio::ip::make_address("127.0.0.1"), rig.map->port());
    std::vector<std::unique_ptr<tcp::socket>> streams;
    int live = 0, refused = 0;
    for (int i = 0; i < 100; ++i) {
        auto s = std::make_unique<tcp::socket>(client);
        s->connect(at);
        asio::write(*s, asio::buffer(std::string("GET /events HTTP/1.1\r\nHost: localhost\r\n\r\n")));
        std::string head;
        asio::read_until(*s, asio::dynamic_buffer(head), "\r\n");
        const auto line = head.substr(0, head.find("\r\n"));
        live += line == "HTTP/1.1 200 OK" ? 1 : 0;
        refused += line.starts_with("HTTP/1.1 503") ? 1 : 0;
        streams.push_back(std::move(s));
    }
    EXPECT_EQ(live, static_cast<int>(MapServer::kMaxStreams));
    EXPECT_EQ(refused, 100 - static_cast<int>(MapServer::kMaxStreams));

    std::vector<std::unique_ptr<Client>> kept;
    for (int i = 0; i < 50; ++i) {
        kept.push_back(std::make_unique<Client>(rig.map->port()));
        kept.back()->send("GET /plan.geojson HTTP/1.1\r\nHost: localhost\r\n\r\n");
        ASSERT_EQ(status_line(kept.back()->response()), "HTTP/1.1 200 OK");
    }
    std::vector<std::unique_ptr<tcp::socket>> idle;
    for (int i = 0; i < 450; ++i) {
        idle.push_back(std::make_unique<tcp::socket>(client));
        idle.back()->connect(at);
    }
    const auto asked = std::chrono::steady_clock::now();
    const auto page = rig.get("/");
    const auto took = std::chrono::steady_clock::now() - asked;
    EXPECT_EQ(status_line(page), "HTTP/1.1 200 OK");
    EXPECT_NE(body_of(page).find("<html"), std::string::npos);
    EXPECT_LT(took, std::chrono::seconds(1)) << "the acceptance figure";
    EXPECT_EQ(status_line(rig.get("/track.geojson")), "HTTP/1.1 200 OK");
    MapServer::Counts counts;
    rig.on_strand([&] { counts = rig.map->counts(); });
    EXPECT_EQ(counts.streams, MapServer::kMaxStreams) << "the live maps stay open";
    EXPECT_EQ(counts.refused_streams, 100u - MapServer::kMaxStreams);
    EXPECT_GE(counts.evicted_idle, 500u - MapServer::kMaxConnections);
    EXPECT_EQ(counts.refused_busy, 0u);
    EXPECT_EQ(counts.accept_errors, 0u);
    std::cout << "[ figures ] GET / with 32 live maps, 68 refused and 500 idle connections: "
              << std::chrono::duration_cast<std::chrono::microseconds>(took).count() / 1000.0 << " ms; "
              << counts.evicted_idle << " idle connections closed for newcomers\n";
}

TEST(MapServer, ABusyPortIsReportedForPeople) {
    Rig first;
    MapConfig config;
    config.listen = "127.0.0.1:" + std::to_string(first.map->port());
    asio::io_context io;
    MapServer second(io.get_executor(), config, {});
    const auto error = second.start();
    EXPECT_NE(error.find("cannot listen on 127.0.0.1:"), std::string::npos) << error;
    MapConfig bad;
    bad.listen = "nowhere";
    MapServer third(io.get_executor(), bad, {});
    EXPECT_EQ(third.start(), "cannot listen on nowhere: give HOST:PORT");
}

// The map words the vehicle's events as watch and log do: in plan terms, once per waypoint; the window's
// slot events go to the page as debug lines only. The link, once down, says since when and keeps its last
// figures apart; the position's age counts from when the hub had it.
TEST(MapServer, EventsInPlanTermsTheLinkDownSinceAndThePositionsAge) {
    Rig rig;
    groundlink::protocol::Telemetry t;
    t.lat_deg = 41.5;
    t.lon_deg = 2.5;
    t.plan_state = 1;
    t.next_waypoint = 4;
    t.plan_element = 2;
    using groundlink::protocol::Event;
    rig.on_strand([&] {
        rig.map->set_plan(Json::parse(R"({"name":"p","elements":[],"no_fly":[],"waypoints":12})"));
        rig.map->add_position(t, std::chrono::system_clock::now());
        rig.map->set_link({{"link", "up"}, {"rtt_ms", 84}, {"loss", 0.02}});
        for (const char* text : {"autopilot: Reached waypoint #5 dist 1m", "mission slot 5 reached",
                                 "autopilot: Flight plan received", "plan waypoint 3 reached",
                                 "plan waypoint 3 reached", "autopilot mode AUTO -> AUTO"}) {
            rig.map->add_event(Event{Event::Severity::Info, text});
        }
        rig.map->set_link({{"link", "down"}, {"rtt_ms", 84}, {"loss", 0.0}});
    });
    const auto state_now = [&] {
        asio::io_context client;
        tcp::socket s(client);
        s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), rig.map->port()));
        asio::write(s, asio::buffer(std::string("GET /events HTTP/1.1\r\nHost: localhost\r\n\r\n")));
        std::string buffer;
        asio::read_until(s, asio::dynamic_buffer(buffer), "\r\n\r\n");
        buffer.erase(0, buffer.find("\r\n\r\n") + 4);
        return read_events(s, buffer, 1).at(0).second;
    };
    const auto state = state_now();
    const auto& events = state["events"];
    ASSERT_EQ(events.size(), 6u) << events.dump();
    std::vector<std::string> shown;
    for (const auto& e : events) {
        if (!e["debug"].get<bool>()) {
            shown.push_back(e["text"]);
        }
    }
    ASSERT_EQ(shown.size(), 1u) << events.dump();
    EXPECT_EQ(shown[0], "waypoint 4 of 12 reached");
    EXPECT_EQ(events[1]["raw"], "mission slot 5 reached") << "the debug view's words";
    EXPECT_EQ(events[3]["raw"], "plan waypoint 3 reached");

    EXPECT_EQ(state["link"]["link"], "down");
    ASSERT_TRUE(state["link"]["down_since"].is_string()) << state["link"].dump();
    EXPECT_EQ(state["link"]["last"]["rtt_ms"], 84) << "the figures of the link when it was up";
    EXPECT_EQ(state["link"]["last"]["loss"], 0.02);
    EXPECT_GE(state["position"]["age_s"].get<double>(), 0.0);
    EXPECT_EQ(state["position"]["plan"], "running");
    EXPECT_EQ(state["position"]["next_waypoint"], 4);
    EXPECT_EQ(state["position"]["plan_element"], 2);

    // Down since the first report of it, not the latest: wait until the clock shows another second.
    const auto since = state["link"]["down_since"].get<std::string>();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (utc_time(std::chrono::system_clock::now()) == since &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    rig.on_strand([&] { rig.map->set_link({{"link", "down"}}); });
    const auto later = state_now();
    EXPECT_EQ(later["link"]["down_since"], since);
    rig.on_strand([&] { rig.map->set_link({{"link", "up"}, {"rtt_ms", 90}}); });
    const auto up = state_now();
    EXPECT_FALSE(up["link"].contains("down_since")) << up["link"].dump();
    EXPECT_EQ(up["link"]["rtt_ms"], 90);
}

}  // namespace
}  // namespace airseg::ground
