#include "ground/map/map_server.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <deque>
#include <filesystem>
#include <set>
#include <utility>
#include <variant>

#include "base/file_text.hpp"
#include "ground/map/http.hpp"
#include "ground/map/map_web_source.hpp"
#include "ground/map/plan_export.hpp"
#include "ground/map/request_guard.hpp"
#include "ground/map/request_reader.hpp"
#include "groundside/watch_view.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::ground {

using Json = nlohmann::json;
using asio::ip::tcp;

namespace {

// The event streams' comment line, which keeps proxies and the browser's stream open.
constexpr auto kKeepAlive = std::chrono::seconds(15);
constexpr auto kAcceptRetry = std::chrono::milliseconds(100);
constexpr std::size_t kMaxHeadBytes = 16 * 1024;
constexpr std::size_t kMaxHeaders = 64;
constexpr std::size_t kMaxTargetBytes = 2048;
constexpr std::size_t kEventsKept = 200;
constexpr std::size_t kMaxFileBytes = 8u << 20;
// A browser that stops reading (a sleeping laptop) is dropped rather than buffered for without end.
constexpr std::size_t kMaxQueuedBytes = 4u << 20;
// The largest plan airsegd takes (kMaxPlanTextBytes) plus room for its JSON escaping.
constexpr std::size_t kMaxBodyBytes = 20u << 20;

std::string dump(const Json& j) {
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

Json empty_plan() {
    return {{"name", nullptr}, {"elements", Json::array()}, {"no_fly", Json::array()}};
}

/// A path below a served directory: plain names only, so that no request reaches outside it.
bool safe_relative_path(std::string_view rest) {
    if (rest.empty() || rest.size() > 256) {
        return false;
    }
    std::size_t start = 0;
    while (start <= rest.size()) {
        const auto slash = rest.find('/', start);
        const auto seg =
            rest.substr(start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
        if (seg.empty() || seg == "." || seg == "..") {
            return false;
        }
        for (char c : seg) {
            const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                            c == '.' || c == '-' || c == '_';
            if (!ok) {
                return false;
            }
        }
        if (slash == std::string_view::npos) {
            break;
        }
        start = slash + 1;
    }
    return true;
}

std::optional<std::string> read_file(const std::filesystem::path& path) {
    auto file = read_file_text(path.string(), kMaxFileBytes);  // a regular file only, never blocking
    if (!file.ok()) {
        return std::nullopt;
    }
    return std::move(file.text);
}

/// The command a map button may send, checked and reduced to the fields it may carry; or why not.
std::variant<Json, std::string> map_command(const std::string& body) {
    const Json req = Json::parse(body, nullptr, false);
    if (req.is_discarded() || !req.is_object()) {
        return std::string("the body must be a JSON object such as {\"cmd\":\"plan.pause\"}");
    }
    const auto cmd = req.find("cmd");
    if (cmd == req.end() || !cmd->is_string()) {
        return std::string("\"cmd\" is missing");
    }
    const auto& name = cmd->get_ref<const std::string&>();
    Json out = {{"cmd", name}};
    if (name == "plan.pause" || name == "plan.resume") {
        return out;
    }
    if (name == "plan.skip") {
        if (const auto i = req.find("index"); i != req.end() && i->is_number_unsigned()) {
            out["index"] = *i;
        } else if (const auto e = req.find("element"); e != req.end() && e->is_string()) {
            out["element"] = *e;
        } else {
            return std::string("plan.skip needs \"index\" (a waypoint number) or \"element\" (a name)");
        }
        return out;
    }
    if (name == "plan.load") {
        const auto text = req.find("text");
        if (text == req.end() || !text->is_string() || text->get_ref<const std::string&>().empty()) {
            return std::string("plan.load needs \"text\": the plan itself (the map sends no file names)");
        }
        out["text"] = *text;
        const auto source = req.find("source");
        out["source"] = source != req.end() && source->is_string() ? *source : Json("map");
        if (const auto paused = req.find("paused"); paused != req.end()) {
            if (!paused->is_boolean()) {
                return std::string("\"paused\" must be true or false");
            }
            out["paused"] = *paused;
        }
        return out;
    }
    return "\"" + name + "\" is not a map command (plan.load, plan.pause, plan.resume, plan.skip)";
}

struct Listen {
    asio::ip::address address;
    std::uint16_t port = 0;
    std::string error;
};

Listen parse_listen(const std::string& listen) {
    Listen out;
    const auto colon = listen.rfind(':');
    if (colon == std::string::npos) {
        out.error = "give HOST:PORT";
        return out;
    }
    std::string host = listen.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
        host = host.substr(1, host.size() - 2);
    }
    if (host == "localhost") {
        host = "127.0.0.1";
    }
    boost::system::error_code ec;
    out.address = asio::ip::make_address(host, ec);
    if (ec) {
        out.error = "\"" + host + "\" is not an IP address";
        return out;
    }
    const std::string port = listen.substr(colon + 1);
    unsigned value = 0;
    const auto [ptr, perr] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (port.empty() || perr != std::errc() || ptr != port.data() + port.size() || value > 65535) {
        out.error = "\"" + port + "\" is not a port number";
        return out;
    }
    out.port = static_cast<std::uint16_t>(value);
    return out;
}

}  // namespace

std::string map_web_dir(const std::string& configured) {
    if (!configured.empty()) {
        return configured;
    }
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::path(AIRSEG_MAP_WEB_INSTALLED) / "index.html", ec)) {
        return AIRSEG_MAP_WEB_INSTALLED;
    }
    return map_web_source_dir();
}

class Session;

struct MapServer::Impl : std::enable_shared_from_this<MapServer::Impl> {
    Impl(asio::any_io_executor ex, MapConfig cfg, CommandSink s)
        : strand(std::move(ex)),
          config(std::move(cfg)),
          web_dir(map_web_dir(config.web_dir)),
          sink(std::move(s)),
          acceptor(strand),
          accept_retry(strand),
          keepalive(strand) {}

    void accept();
    /// Closes the connection that has waited longest for a request, if any.
    void make_room();
    void tick();
    void broadcast(const std::string& event, const Json& data);
    Json state() const;
    Json position_json(const TrackPoint& p) const;

    asio::any_io_executor strand;
    MapConfig config;
    std::string web_dir;
    CommandSink sink;
    tcp::acceptor acceptor;
    asio::steady_timer accept_retry;
    std::uint64_t accepted = 0;
    MapServer::Counts counts;
    asio::steady_timer keepalive;
    bool running = false;
    std::set<std::shared_ptr<Session>> sessions;

    Json plan = empty_plan();
    std::deque<TrackPoint> track;
    Json last_position;  // with the fields the track leaves out (battery, plan state)
    Json fix;            // {"valid": whether the last sample had a position, ...}; null before any sample
    RequestGuard guard;
    LimitedLog log;  // refusals: any page the operator opens can make them
    Json link;
    std::optional<std::chrono::system_clock::time_point> down_since;
    Json last_up;  // the link's figures the last time it was up
    std::chrono::steady_clock::time_point last_position_at{};
    groundside::EventWording wording;
    std::deque<Json> events;

    void push_event(Json e);
};

/// One browser connection: requests read with Beast (http::RequestReader) and answered one at a time, in
/// order, on a kept-alive connection; or, after GET /events, an event stream until either side goes.
class Session : public std::enable_shared_from_this<Session> {
  public:
    Session(std::shared_ptr<MapServer::Impl> server, tcp::socket socket)
        : server_(std::move(server)),
          socket_(std::move(socket)),
          timer_(server_->strand),
          reader_(http::Limits{kMaxHeadBytes, kMaxHeaders, kMaxTargetBytes, kMaxBodyBytes}) {}

    void start() { wait_for_request(); }

    void refuse_busy() {
        phase_ = Phase::Answering;
        send(http::render(http::error_reply(503, "too many connections to the map"), {}), true);
    }

    /// Connected, and no request being answered: what a newcomer may take the place of.
    bool waiting_for_request() const { return phase_ == Phase::Reading && !closed_; }
    /// Since when it waits: connected, or its last answer sent.
    TimePoint waiting_since() const { return waiting_since_; }

    /// One server-sent event, if this is an event stream.
    void event(const std::string& text) {
        if (phase_ == Phase::Streaming) {
            send(text, false);
        }
    }

    void close() {
        if (closed_) {
            return;
        }
        closed_ = true;
        if (phase_ == Phase::Streaming) {
            --server_->counts.streams;
        }
        ++timer_generation_;
        timer_.cancel();
        boost::system::error_code ignored;
        socket_.shutdown(tcp::socket::shutdown_both, ignored);
        socket_.close(ignored);
        server_->sessions.erase(shared_from_this());
    }

  private:
    enum class Phase { Reading, Answering, Streaming };

    /// One timer per connection, for whichever deadline its phase has; a newer arming disowns older waits.
    template <typename F>
    void arm(std::chrono::steady_clock::duration after, F on_expiry) {
        const auto generation = ++timer_generation_;
        timer_.expires_after(after);
        timer_.async_wait([self = shared_from_this(), generation, on_expiry](boost::system::error_code ec) {
            if (!ec && !self->closed_ && generation == self->timer_generation_) {
                on_expiry(*self);
            }
        });
    }

    void wait_for_request() {
        phase_ = Phase::Reading;
        waiting_since_ = SteadyClock::now();
        arm(server_->config.request_deadline, [](Session& self) { self.on_request_deadline(); });
        on_reader(reader_.feed({}));  // a request pipelined behind the last one may be here already
    }

    void on_request_deadline() {
        if (phase_ != Phase::Reading) {
            return;
        }
        ++server_->counts.request_timeouts;
        if (requests_ > 0 && !reader_.started()) {
            close();  // a kept-alive connection with nothing more to ask: closed without a word
            return;
        }
        answer({}, http::error_reply(408, "the request did not arrive in time"), true);
    }

    void do_read() {
        socket_.async_read_some(asio::buffer(buf_),
                                [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                                    self->on_read(ec, n);
                                });
    }

    void on_read(boost::system::error_code ec, std::size_t n) {
        if (ec || closed_) {
            close();
            return;
        }
        if (phase_ == Phase::Streaming) {
            // The browser has nothing more to say; reading on only notices when it goes.
            do_read();
            return;
        }
        if (phase_ == Phase::Reading) {
            on_reader(reader_.feed(std::string_view(buf_.data(), n)));
        }
        // Answering (a 408 on its way): the answer's end closes the connection.
    }

    void on_reader(http::RequestReader::State state) {
        switch (state) {
            case http::RequestReader::State::Incomplete:
                do_read();
                break;
            case http::RequestReader::State::Failed:
                // The request's end is unknown: nothing after it can be read.
                answer({}, http::error_reply(reader_.error_status(), reader_.error()), true);
                break;
            case http::RequestReader::State::Done:
                ++requests_;
                phase_ = Phase::Answering;
                ++timer_generation_;  // no request deadline while the vehicle answers a command
                timer_.cancel();
                handle(reader_.take());
                break;
        }
    }

    /// How an answer to `req` is framed; kept alive when the client asked and `close` does not say otherwise.
    http::Framing framing_of(const http::Request& req, bool close) const {
        return {req.version, req.method == "HEAD", req.keep_alive && !close && server_->running};
    }

    void answer(http::Framing framing, const http::Reply& reply, bool close = false) {
        framing.keep_alive = framing.keep_alive && !close;
        send(http::render(reply, framing), !framing.keep_alive);
    }

    void reply(const http::Request& req, const http::Reply& reply) { answer(framing_of(req, false), reply); }
    void refuse(const http::Request& req, const http::Reply& reply) { answer(framing_of(req, true), reply); }

    void reply_json(const http::Request& req, int status, const Json& body) {
        reply(req, {status, "application/json", dump(body), {}});
    }

    /// "/events?for=S" ends the stream after S seconds: a snapshot of the live map (a headless browser only
    /// renders once the page's requests are over) without a stream that never ends.
    void end_stream_after(const std::string& query) {
        if (!query.starts_with("for=")) {
            return;
        }
        const auto text = query.substr(4);
        int seconds = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seconds);
        if (ec != std::errc() || end != text.data() + text.size() || seconds < 1 || seconds > 3600) {
            return;
        }
        arm(std::chrono::seconds(seconds),
            [](Session& self) { self.send(": end of the snapshot\n\n", true); });
    }

    void send(std::string bytes, bool close_after) {
        if (closed_) {
            return;
        }
        close_after_ = close_after_ || close_after;
        queued_ += bytes.size();
        if (phase_ == Phase::Streaming && queued_ > kMaxQueuedBytes) {
            close();
            return;
        }
        out_.push_back(std::move(bytes));
        if (out_.size() == 1) {
            write();
        }
    }

    void write() {
        if (phase_ != Phase::Streaming) {
            // A client that does not read its answers gives up its connection.
            arm(server_->config.answer_deadline, [](Session& self) {
                ++self.server_->counts.answers_cut_off;
                self.close();
            });
        }
        asio::async_write(
            socket_, asio::buffer(out_.front()),
            [self = shared_from_this()](boost::system::error_code ec, std::size_t) { self->on_written(ec); });
    }

    void on_written(boost::system::error_code ec) {
        if (ec || closed_) {
            close();
            return;
        }
        queued_ -= out_.front().size();
        out_.pop_front();
        if (!out_.empty()) {
            write();
        } else if (close_after_) {
            close();
        } else if (phase_ == Phase::Answering) {
            wait_for_request();
        }
    }

    void handle(const http::Request& req);
    void stream(const http::Request& req);
    void serve_file(const http::Request& req, const std::string& dir, std::string_view rest);
    void command(const http::Request& req);

    std::shared_ptr<MapServer::Impl> server_;
    tcp::socket socket_;
    asio::steady_timer timer_;
    std::uint64_t timer_generation_ = 0;
    http::RequestReader reader_;
    std::array<char, 8192> buf_{};
    std::deque<std::string> out_;
    std::size_t queued_ = 0;
    Phase phase_ = Phase::Reading;
    std::uint64_t requests_ = 0;
    bool close_after_ = false;
    bool closed_ = false;
    TimePoint waiting_since_ = SteadyClock::now();
};

void Session::handle(const http::Request& req) {
    const std::string& path = req.path;
    const bool head = req.method == "HEAD";
    auto& s = *server_;
    if (const auto why = s.guard.host_refusal(req)) {
        s.log.log("map: refused a request for another host", SteadyClock::now(), spdlog::level::warn,
                  "map: refused {} {}: {}", req.method, req.path.substr(0, 100), *why);
        refuse(req, http::error_reply(403, *why));
        return;
    }
    if (path == "/api/command") {
        if (req.method != "POST") {
            reply(req, http::error_reply(405, "use POST", {{"Allow", "POST"}}));
            return;
        }
        command(req);
        return;
    }
    if (req.method != "GET" && !head) {
        reply(req, http::error_reply(405, "only GET and HEAD here", {{"Allow", "GET, HEAD"}}));
        return;
    }
    const auto attachment = [](const char* name) {
        return std::vector<std::pair<std::string, std::string>>{
            {"Content-Disposition", std::string("attachment; filename=\"") + name + "\""}};
    };
    if (path == "/" || path == "/index.html") {
        serve_file(req, s.web_dir, "index.html");
    } else if (path.starts_with("/static/")) {
        serve_file(req, s.web_dir, std::string_view(path).substr(8));
    } else if (path.starts_with("/leaflet/")) {
        serve_file(req, s.config.leaflet_dir, std::string_view(path).substr(9));
    } else if (path == "/events") {
        stream(req);
    } else if (path == "/plan.geojson") {
        reply(req, {200, "application/geo+json", dump(plan_geojson(s.plan)), {}});
    } else if (path == "/track.geojson") {
        reply(req, {200, "application/geo+json", dump(track_geojson(s.track)), {}});
    } else if (path == "/plan.kml") {
        reply(req, {200, "application/vnd.google-earth.kml+xml", plan_kml(s.plan), attachment("plan.kml")});
    } else if (path == "/track.kml") {
        reply(req,
              {200, "application/vnd.google-earth.kml+xml", track_kml(s.track), attachment("track.kml")});
    } else {
        reply(req, http::error_reply(404, "no such page: " + path));
    }
}

void Session::stream(const http::Request& req) {
    auto& s = *server_;
    const auto framing = framing_of(req, true);
    if (framing.head) {
        send(http::render_stream_head(framing), true);
        return;
    }
    if (s.counts.streams >= MapServer::kMaxStreams) {
        ++s.counts.refused_streams;
        s.log.log("map: refused an event stream", SteadyClock::now(), spdlog::level::warn,
                  "map: refused an event stream: {} are open (close a map tab)", MapServer::kMaxStreams);
        refuse(req,
               http::error_reply(503, "too many live maps open (" + std::to_string(MapServer::kMaxStreams) +
                                          "); close a map tab"));
        return;
    }
    phase_ = Phase::Streaming;
    ++s.counts.streams;
    send(http::render_stream_head(framing), false);
    send("retry: 2000\nevent: state\ndata: " + dump(s.state()) + "\n\n", false);
    end_stream_after(req.query);
    do_read();
}

void Session::serve_file(const http::Request& req, const std::string& dir, std::string_view rest) {
    if (!safe_relative_path(rest)) {
        reply(req, http::error_reply(404, "no such file"));
        return;
    }
    auto content = read_file(std::filesystem::path(dir) / std::string(rest));
    if (!content) {
        reply(req, http::error_reply(404, "no such file: " + std::string(rest)));
        return;
    }
    reply(req, {200, std::string(http::content_type_for(rest)), std::move(*content), {}});
}

void Session::command(const http::Request& req) {
    auto& s = *server_;
    if (!s.config.control) {
        reply_json(req, 403,
                   {{"ok", false},
                    {"error", "this map only watches: it was started without control of the vehicle"}});
        return;
    }
    if (const auto why = s.guard.command_refusal(req)) {
        s.log.log("map: refused a command", SteadyClock::now(), spdlog::level::warn,
                  "map: refused a command: {}", *why);
        reply_json(req, 403, {{"ok", false}, {"error", *why}});
        return;
    }
    auto checked = map_command(req.body);
    if (auto* why = std::get_if<std::string>(&checked)) {
        reply_json(req, 400, {{"ok", false}, {"error", *why}});
        return;
    }
    if (!s.sink) {
        reply_json(req, 503, {{"ok", false}, {"error", "no vehicle link to send the command on"}});
        return;
    }
    const auto& request = std::get<Json>(checked);
    s.log.log("map: command", SteadyClock::now(), spdlog::level::info, "map: command {} from the page of {}",
              request.value("cmd", std::string()),
              req.header("origin").value_or(req.header("host").value_or("")));
    auto once = std::make_shared<bool>(false);
    s.sink(std::move(std::get<Json>(checked)),
           [self = shared_from_this(), framing = framing_of(req, false), once](Json answer) {
               if (std::exchange(*once, true)) {
                   return;
               }
               self->answer(framing, {200, "application/json", dump(answer), {}});
           });
}

void MapServer::Impl::accept() {
    acceptor.async_accept([self = shared_from_this()](boost::system::error_code ec, tcp::socket socket) {
        if (!self->running) {
            return;
        }
        if (ec) {
            // Out of descriptors (EMFILE) or the like: free one if an idle connection holds it, and try again
            // shortly rather than spinning on the error.
            ++self->counts.accept_errors;
            self->log.log("map: accept failed", SteadyClock::now(), spdlog::level::warn,
                          "map: cannot accept a connection: {}", ec.message());
            self->make_room();
            self->accept_retry.expires_after(kAcceptRetry);
            self->accept_retry.async_wait([self](boost::system::error_code e) {
                if (!e && self->running) {
                    self->accept();
                }
            });
            return;
        }
        ++self->accepted;
        ++self->counts.accepted;
        auto session = std::make_shared<Session>(self, std::move(socket));
        if (self->sessions.size() - self->counts.streams >= kMaxConnections) {
            self->make_room();
        }
        if (self->sessions.size() - self->counts.streams >= kMaxConnections) {
            ++self->counts.refused_busy;
            self->log.log("map: refused a connection", SteadyClock::now(), spdlog::level::warn,
                          "map: refused a connection: all {} are being answered", kMaxConnections);
            session->refuse_busy();  // kept alive by its write until the answer is out
        } else {
            self->sessions.insert(session);
            session->start();
        }
        self->accept();
    });
}

void MapServer::Impl::make_room() {
    std::shared_ptr<Session> oldest;
    for (const auto& session : sessions) {
        if (session->waiting_for_request() &&
            (!oldest || session->waiting_since() < oldest->waiting_since())) {
            oldest = session;
        }
    }
    if (oldest) {
        ++counts.evicted_idle;
        oldest->close();
    }
}

void MapServer::Impl::tick() {
    keepalive.expires_after(kKeepAlive);
    keepalive.async_wait([self = shared_from_this()](boost::system::error_code ec) {
        if (ec || !self->running) {
            return;
        }
        // A comment line: keeps idle proxies and the browser's stream open, and finds gone browsers.
        for (const auto& session : std::vector(self->sessions.begin(), self->sessions.end())) {
            session->event(": keepalive\n\n");
        }
        self->tick();
    });
}

void MapServer::Impl::broadcast(const std::string& event, const Json& data) {
    if (!running) {
        return;
    }
    const std::string text = "event: " + event + "\ndata: " + dump(data) + "\n\n";
    for (const auto& session : std::vector(sessions.begin(), sessions.end())) {
        session->event(text);
    }
}

Json MapServer::Impl::position_json(const TrackPoint& p) const {
    return {{"lat", p.lat},         {"lon", p.lon},     {"alt", p.alt},
            {"heading", p.heading}, {"speed", p.speed}, {"t", utc_time(p.at)}};
}

Json MapServer::Impl::state() const {
    Json points = Json::array();
    for (const auto& p : track) {
        points.push_back(Json::array({p.lat, p.lon}));
    }
    Json position = last_position;
    if (position.is_object()) {
        // Its age as the hub sees it: the page counts on from there with its own clock.
        position["age_s"] =
            std::round(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - last_position_at).count() *
                10.0) /
            10.0;
    }
    Json out = {{"plan", plan},
                {"track", std::move(points)},
                {"position", std::move(position)},
                {"fix", fix},
                {"link", link},
                {"events", Json(events)},
                {"control", config.control},
                {"tile_url", config.tile_url}};
    if (config.control) {
        // Only the map's own page reads this stream: no CORS header lets another origin's page read it, and
        // a request naming another host (DNS rebinding) is refused.
        out["token"] = guard.token;
    }
    return out;
}

MapServer::MapServer(asio::any_io_executor strand, MapConfig config, CommandSink sink)
    : impl_(std::make_shared<Impl>(std::move(strand), std::move(config), std::move(sink))) {}

MapServer::~MapServer() {
    stop();
}

std::string MapServer::start() {
    auto& s = *impl_;
    const auto listen = parse_listen(s.config.listen);
    if (!listen.error.empty()) {
        return "cannot listen on " + s.config.listen + ": " + listen.error;
    }
    boost::system::error_code ec;
    const tcp::endpoint endpoint(listen.address, listen.port);
    s.acceptor.open(endpoint.protocol(), ec);
    if (!ec) {
        s.acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    }
    if (!ec) {
        s.acceptor.bind(endpoint, ec);
    }
    if (!ec) {
        s.acceptor.listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        boost::system::error_code ignored;
        s.acceptor.close(ignored);
        return "cannot listen on " + s.config.listen + ": " + ec.message();
    }
    s.guard.token = random_token();
    s.guard.names.clear();
    for (const auto& name : s.config.host_names) {
        std::string lowered = name;
        std::transform(lowered.begin(), lowered.end(), lowered.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        s.guard.names.push_back(std::move(lowered));
    }
    s.running = true;
    s.accept();
    s.tick();
    return {};
}

void MapServer::stop() {
    auto& s = *impl_;
    if (!s.running) {
        return;
    }
    s.running = false;
    boost::system::error_code ignored;
    s.acceptor.close(ignored);
    s.accept_retry.cancel();
    s.keepalive.cancel();
    for (const auto& session : std::vector(s.sessions.begin(), s.sessions.end())) {
        session->close();
    }
}

std::uint16_t MapServer::port() const {
    boost::system::error_code ec;
    const auto endpoint = impl_->acceptor.local_endpoint(ec);
    return ec ? 0 : endpoint.port();
}

std::uint64_t MapServer::connections_accepted() const {
    return impl_->accepted;
}

MapServer::Counts MapServer::counts() const {
    return impl_->counts;
}

void MapServer::set_plan(const Json& geometry) {
    impl_->plan = geometry.is_object() ? geometry : empty_plan();
    const auto count = impl_->plan.find("waypoints");
    impl_->wording.set_waypoints(count != impl_->plan.end() && count->is_number_unsigned()
                                     ? std::optional<std::uint64_t>(count->get<std::uint64_t>())
                                     : std::nullopt);
    impl_->broadcast("plan", impl_->plan);
}

void MapServer::add_position(const groundlink::protocol::Telemetry& t,
                             std::chrono::system_clock::time_point at) {
    auto& s = *impl_;
    s.wording.set_plan_state(t.plan_state);
    if (t.no_position) {
        // No place to show: the vehicle and its track stay where they were last known, and the page says
        // "no fix" from the first such sample until the next position.
        if (!s.fix.is_object() || s.fix.value("valid", true)) {
            s.fix = {{"valid", false}, {"gps_fix", t.gps_fix}, {"t", utc_time(at)}};
            s.broadcast("fix", s.fix);
        }
        return;
    }
    s.fix = {{"valid", true}};
    const TrackPoint p{t.lat_deg, t.lon_deg, t.alt_m, t.heading_deg, t.ground_speed_mps, at};
    s.track.push_back(p);
    if (s.track.size() > kTrackPoints) {
        s.track.pop_front();
    }
    Json j = s.position_json(p);
    j["battery_v"] = t.battery_v;
    j["battery_pct"] = t.battery_pct ? Json(*t.battery_pct) : Json(nullptr);
    j["gps_fix"] = t.gps_fix;
    j["satellites"] = t.satellites;
    j["plan_state"] = t.plan_state;
    j["next_waypoint"] = t.next_waypoint;
    j["plan"] = groundside::plan_state_name(t.plan_state);
    j["plan_element"] = t.plan_element;
    j["state"] = groundlink::protocol::vehicle_state_name(t.vehicle_state);
    s.last_position = j;
    s.last_position_at = std::chrono::steady_clock::now();
    s.broadcast("position", j);
}

void MapServer::set_link(const Json& link) {
    auto& s = *impl_;
    Json j = link.is_object() ? link : Json::object();
    if (j.value("link", std::string()) == "up") {
        s.down_since.reset();
        s.last_up = j;
    } else {
        if (!s.down_since) {
            s.down_since = std::chrono::system_clock::now();
        }
        j["down_since"] = utc_time(*s.down_since);
        j["last"] = s.last_up.is_object() ? Json{{"rtt_ms", s.last_up.value("rtt_ms", Json())},
                                                 {"loss", s.last_up.value("loss", Json())}}
                                          : Json();
    }
    s.link = j;
    s.broadcast("link", j);
}

void MapServer::Impl::push_event(Json e) {
    events.push_back(e);
    if (events.size() > kEventsKept) {
        events.pop_front();
    }
    broadcast("event", e);
}

void MapServer::add_event(const groundlink::protocol::Event& e) {
    auto& s = *impl_;
    const auto worded = s.wording.word(e, std::chrono::steady_clock::now());
    s.push_event(
        {{"t", utc_time(std::chrono::system_clock::now())},
         {"text", worded.text},
         {"raw", worded.raw},
         {"debug", worded.debug},
         {"severity", worded.severity == groundlink::protocol::Event::Severity::Error     ? "error"
                      : worded.severity == groundlink::protocol::Event::Severity::Warning ? "warning"
                                                                                          : "info"}});
}

void MapServer::add_event(const std::string& text) {
    impl_->push_event({{"t", utc_time(std::chrono::system_clock::now())},
                       {"text", text},
                       {"raw", text},
                       {"debug", false},
                       {"severity", "info"}});
}

}  // namespace airseg::ground
