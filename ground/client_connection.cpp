#include "ground/client_connection.hpp"

#include <fmt/format.h>

namespace airseg::ground {

ClientConnection::ClientConnection(Socket socket, std::uint32_t id, std::string peer, Handlers handlers)
    : socket_(std::move(socket)), id_(id), peer_(std::move(peer)), handlers_(std::move(handlers)) {}

void ClientConnection::start() {
    read();
}

void ClientConnection::read() {
    socket_.async_read_some(
        asio::buffer(buffer_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
            if (self->closed_) {
                return;
            }
            if (ec) {
                self->finish(ec == asio::error::eof ? "disconnected" : "read failed: " + ec.message());
                return;
            }
            if (!self->reader_.push(std::span(self->buffer_.data(), n))) {
                self->close("broken stream: " + self->reader_.error());
                return;
            }
            while (auto frame = self->reader_.next()) {
                self->handlers_.on_frame(*self, std::move(*frame));
                if (self->closed_ || self->closing_) {
                    return;
                }
            }
            self->read();
        });
}

void ClientConnection::send(std::vector<std::uint8_t> frame) {
    if (closed_ || closing_) {
        return;
    }
    queued_bytes_ += frame.size();
    queue_.push_back(std::move(frame));
    if (queued_bytes_ > kMaxQueued) {
        // Its queue is stuck, so no closing message would get through either; the buffers stay until the
        // write in flight completes.
        finish(fmt::format("not reading: more than {} bytes waited for it", kMaxQueued));
        return;
    }
    write_next();
}

void ClientConnection::write_next() {
    if (writing_ || queue_.empty()) {
        if (!writing_ && closing_ && !closed_) {
            finish(close_reason_);
        }
        return;
    }
    writing_ = true;
    asio::async_write(socket_, asio::buffer(queue_.front()),
                      [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                          self->writing_ = false;
                          if (self->closed_) {
                              return;
                          }
                          self->queued_bytes_ -= self->queue_.front().size();
                          self->queue_.pop_front();
                          if (ec) {
                              self->finish("write failed: " + ec.message());
                              return;
                          }
                          self->write_next();
                      });
}

void ClientConnection::close(const std::string& why) {
    if (closed_ || closing_) {
        return;
    }
    queue_.push_back(groundside::hub::encode_json({{"error", why}}));
    queued_bytes_ += queue_.back().size();
    closing_ = true;
    close_reason_ = why;
    write_next();
}

void ClientConnection::finish(const std::string& why) {
    if (closed_) {
        return;
    }
    closed_ = true;
    boost::system::error_code ignored;
    socket_.shutdown(Socket::shutdown_both, ignored);
    socket_.close(ignored);
    if (handlers_.on_closed) {
        handlers_.on_closed(*this, why);
    }
}

}  // namespace airseg::ground
