// @brief Disjoint sets over indices 0..n−1 (union-find with path halving),
// each set represented by its lowest index, so that the result does not
// depend on the order of the unions: welded vertices and mesh parts
// (sim/collision) use it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace hp {

class UnionFind {
  public:
    explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }

    /// The representative (lowest index) of i's set.
    uint32_t find(uint32_t i) {
        while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
        return i;
    }
    /// Joins the sets of a and b; the lower representative wins.
    void unite(uint32_t a, uint32_t b) {
        a = find(a), b = find(b);
        if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    }
    /// Every index's representative.
    std::vector<uint32_t> roots() {
        for (uint32_t i = 0; i < uint32_t(parent_.size()); ++i) parent_[i] = find(i);
        return parent_;
    }

  private:
    std::vector<uint32_t> parent_;
};

}  // namespace hp
