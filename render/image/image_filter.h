// Single-channel float planes and separable convolution, the building block
// of the image metrics (render/compare/ssim.h, render/compare/flip.h).
//
// Borders replicate the edge pixel (clamp-to-edge), as the FLIP reference
// does: a constant image stays constant (up to rounding) under any normalised
// kernel, so the image border adds no spurious structure or error.
// Rows are filtered in parallel (TBB); every output pixel is a fixed sum in a
// fixed order, so results do not depend on the thread count.
#pragma once

#include <cstddef>
#include <vector>

namespace hp {

/// A single-channel float image, row-major, top row first.
struct ImagePlane {
    int width = 0;
    int height = 0;
    std::vector<float> data;

    ImagePlane() = default;
    ImagePlane(int w, int h, float value = 0.f) : width(w), height(h), data(std::size_t(w) * std::size_t(h), value) {}
    float& at(int x, int y) { return data[std::size_t(y) * width + x]; }
    float at(int x, int y) const { return data[std::size_t(y) * width + x]; }
    std::size_t size() const { return data.size(); }
};

/// A 1-D kernel of odd length 2r+1; tap i weighs the pixel at offset i - r.
using FilterKernel = std::vector<float>;

/// Sampled Gaussian exp(-x²/(2σ²)) for x in [-radius, radius], normalised to sum 1.
FilterKernel gaussianKernel(double sigma, int radius);

/// Convolves every row with `k` (horizontal pass).
ImagePlane convolveRows(const ImagePlane& in, const FilterKernel& k);
/// Convolves every column with `k` (vertical pass).
ImagePlane convolveColumns(const ImagePlane& in, const FilterKernel& k);
/// Horizontal pass with `kx`, then vertical pass with `ky`: the 2-D kernel kx(x)·ky(y).
ImagePlane convolveSeparable(const ImagePlane& in, const FilterKernel& kx, const FilterKernel& ky);

}  // namespace hp
