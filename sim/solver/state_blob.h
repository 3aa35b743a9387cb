// Byte blobs for solver checkpoints: plain arrays appended and read back in
// the same order, with sizes checked, so a restored solver holds exactly the
// bits it saved.
#pragma once

#include "core/errors.h"

#include <cstring>
#include <string>
#include <vector>

namespace hp {

class BlobWriter {
  public:
    template <typename T>
    void put(const T& value) { bytes(&value, sizeof(T)); }
    template <typename T>
    void array(const std::vector<T>& v) {
        put(uint64_t(v.size()));
        bytes(v.data(), v.size() * sizeof(T));
    }
    void bytes(const void* p, size_t n) {
        const char* c = static_cast<const char*>(p);
        data.insert(data.end(), c, c + n);
    }
    std::vector<char> data;
};

class BlobReader {
  public:
    BlobReader(const std::vector<char>& data, std::string what) : data_(data), what_(std::move(what)) {}
    template <typename T>
    T get() {
        T value;
        bytes(&value, sizeof(T));
        return value;
    }
    /// Reads an array that must have `expected` elements (the solver's own size).
    template <typename T>
    void array(std::vector<T>& v, size_t expected) {
        const uint64_t n = get<uint64_t>();
        if (n != expected) throw Error(cat(what_, ": checkpoint holds ", n, " values where ", expected, " are expected"));
        v.resize(n);
        bytes(v.data(), n * sizeof(T));
    }
    void bytes(void* p, size_t n) {
        if (n > data_.size() - pos_) throw Error(what_ + ": checkpoint is truncated");
        std::memcpy(p, data_.data() + pos_, n);
        pos_ += n;
    }
    void finish() const {
        if (pos_ != data_.size()) throw Error(what_ + ": checkpoint has trailing data");
    }

  private:
    const std::vector<char>& data_;
    std::string what_;
    size_t pos_ = 0;
};

}  // namespace hp
