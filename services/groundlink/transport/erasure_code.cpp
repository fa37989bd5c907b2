#include "services/groundlink/transport/erasure_code.hpp"

#include <array>

namespace airseg::groundlink::fec {
namespace {

struct Tables {
    std::array<std::uint8_t, 512> exp{};
    std::array<std::uint8_t, 256> log{};
};

constexpr Tables make_tables() {
    Tables t;
    unsigned x = 1;
    for (unsigned i = 0; i < 255; ++i) {
        t.exp[i] = static_cast<std::uint8_t>(x);
        t.log[x] = static_cast<std::uint8_t>(i);
        x <<= 1;
        if ((x & 0x100U) != 0) {
            x ^= 0x11DU;
        }
    }
    for (unsigned i = 255; i < 512; ++i) {
        t.exp[i] = t.exp[i - 255];
    }
    return t;
}

constexpr Tables kGf = make_tables();

std::uint8_t mul(std::uint8_t a, std::uint8_t b) {
    if (a == 0 || b == 0) {
        return 0;
    }
    return kGf.exp[static_cast<std::size_t>(kGf.log[a]) + kGf.log[b]];
}

std::uint8_t inv(std::uint8_t a) {
    return kGf.exp[255 - kGf.log[a]];  // a != 0
}

std::uint8_t cauchy(std::size_t n, std::size_t parity_index, std::size_t data_index) {
    return inv(static_cast<std::uint8_t>((n + parity_index) ^ data_index));
}

// dst ^= c · src
void mul_add(std::span<std::uint8_t> dst, std::span<const std::uint8_t> src, std::uint8_t c) {
    if (c == 0) {
        return;
    }
    const unsigned lc = kGf.log[c];
    for (std::size_t k = 0; k < dst.size(); ++k) {
        if (src[k] != 0) {
            dst[k] ^= kGf.exp[lc + kGf.log[src[k]]];
        }
    }
}

// Inverts the e×e matrix m (row-major) in place by Gauss–Jordan elimination; false when singular.
bool invert(std::vector<std::uint8_t>& m, std::size_t e) {
    std::vector<std::uint8_t> out(e * e, 0);
    for (std::size_t i = 0; i < e; ++i) {
        out[i * e + i] = 1;
    }
    for (std::size_t col = 0; col < e; ++col) {
        std::size_t pivot = col;
        while (pivot < e && m[pivot * e + col] == 0) {
            ++pivot;
        }
        if (pivot == e) {
            return false;
        }
        if (pivot != col) {
            for (std::size_t k = 0; k < e; ++k) {
                std::swap(m[pivot * e + k], m[col * e + k]);
                std::swap(out[pivot * e + k], out[col * e + k]);
            }
        }
        const std::uint8_t scale = inv(m[col * e + col]);
        for (std::size_t k = 0; k < e; ++k) {
            m[col * e + k] = mul(m[col * e + k], scale);
            out[col * e + k] = mul(out[col * e + k], scale);
        }
        for (std::size_t row = 0; row < e; ++row) {
            const std::uint8_t f = m[row * e + col];
            if (row == col || f == 0) {
                continue;
            }
            for (std::size_t k = 0; k < e; ++k) {
                m[row * e + k] ^= mul(f, m[col * e + k]);
                out[row * e + k] ^= mul(f, out[col * e + k]);
            }
        }
    }
    m = std::move(out);
    return true;
}

}  // namespace

std::vector<std::uint8_t> encode_parity(std::span<const std::span<const std::uint8_t>> data,
                                        std::size_t parity_index) {
    const std::size_t len = data.empty() ? 0 : data[0].size();
    std::vector<std::uint8_t> parity(len, 0);
    for (std::size_t i = 0; i < data.size(); ++i) {
        mul_add(parity, data[i], cauchy(data.size(), parity_index, i));
    }
    return parity;
}

std::optional<std::vector<std::vector<std::uint8_t>>> reconstruct(std::size_t n,
                                                                  std::span<const Shard> shards) {
    if (n == 0 || n > kMaxShards || shards.empty()) {
        return std::nullopt;
    }
    const std::size_t len = shards[0].bytes.size();
    std::vector<const Shard*> by_index(kMaxShards, nullptr);
    std::size_t distinct = 0;
    for (const Shard& s : shards) {
        if (s.index >= kMaxShards || s.bytes.size() != len) {
            return std::nullopt;
        }
        if (by_index[s.index] == nullptr) {
            by_index[s.index] = &s;
            ++distinct;
        }
    }
    if (distinct < n) {
        return std::nullopt;
    }
    std::vector<std::vector<std::uint8_t>> data(n);
    std::vector<std::size_t> missing;
    for (std::size_t i = 0; i < n; ++i) {
        if (by_index[i] != nullptr) {
            data[i].assign(by_index[i]->bytes.begin(), by_index[i]->bytes.end());
        } else {
            missing.push_back(i);
        }
    }
    if (missing.empty()) {
        return data;
    }
    // Syndromes of as many parity shards as there are missing data shards: each parity minus the known
    // data's contribution leaves a combination of the missing shards only.
    const std::size_t e = missing.size();
    std::vector<std::size_t> rows;
    std::vector<std::vector<std::uint8_t>> syndrome;
    for (std::size_t idx = n; idx < kMaxShards && rows.size() < e; ++idx) {
        if (by_index[idx] == nullptr) {
            continue;
        }
        const std::size_t j = idx - n;
        std::vector<std::uint8_t> s(by_index[idx]->bytes.begin(), by_index[idx]->bytes.end());
        for (std::size_t i = 0; i < n; ++i) {
            if (!data[i].empty() || len == 0) {
                mul_add(s, data[i], cauchy(n, j, i));
            }
        }
        rows.push_back(j);
        syndrome.push_back(std::move(s));
    }
    std::vector<std::uint8_t> m(e * e);
    for (std::size_t r = 0; r < e; ++r) {
        for (std::size_t k = 0; k < e; ++k) {
            m[r * e + k] = cauchy(n, rows[r], missing[k]);
        }
    }
    if (!invert(m, e)) {
        return std::nullopt;  // cannot happen for a Cauchy submatrix
    }
    for (std::size_t k = 0; k < e; ++k) {
        auto& out = data[missing[k]];
        out.assign(len, 0);
        for (std::size_t r = 0; r < e; ++r) {
            mul_add(out, syndrome[r], m[k * e + r]);
        }
    }
    return data;
}

}  // namespace airseg::groundlink::fec
