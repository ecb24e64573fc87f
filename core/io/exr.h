// Image files: OpenEXR (linear HDR, float) in and out, and PNG previews.
//
// Every writer goes through core/io/atomic_write.h: it creates the missing folders above its
// path, writes to "<path>.tmp-XXXXXXXX" in the same folder and renames it into place, so a failed
// or interrupted run leaves no partial file. The *Content functions encode an image for
// writeFilesTogether, which writes several files (a render's EXR and PNG) as one set. Readers
// validate before decoding: Debian's OpenEXR 3.1.5 has a known flaw with deep images, so EXR input
// is accepted only after Imf::checkOpenEXRFile passes, deep files are rejected, and sizes are
// capped.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/io/atomic_write.h"

namespace eikon {

struct RgbaImage {
  int width = 0, height = 0;
  std::vector<float> rgba;  ///< rows from the top, 4 floats per pixel
};

/// Read an RGB(A) EXR. Throws std::runtime_error for unreadable, corrupt, deep, tiled-deep or
/// oversized files (width > max_width or height > max_height).
RgbaImage readExrRgba(const std::filesystem::path& path, int max_width, int max_height);

/// One named float channel of an EXR file ("R", "G", "B", or e.g. "S0.550,000000nm").
struct ExrChannel {
  std::string name;
  const float* data;  ///< width*height floats, rows from the top
};

/// Write float channels to an EXR (ZIP compression) atomically.
void writeExr(const std::filesystem::path& path, int width, int height,
              const std::vector<ExrChannel>& channels);

/// Linear RGB floats (3 per pixel) as an EXR with R, G, B channels (ZIP), for writeFilesTogether.
/// The pixels are copied: `rgb` need not outlive the result.
FileContent exrRgbContent(int width, int height, const std::vector<float>& rgb);

/// The spectral channel name of a bin centred at `centreNm`, after Fichet, Pacanowski & Wilkie,
/// "An OpenEXR Layout for Spectral Images" (JCGT 10(3), 2021) and their reference code
/// (github.com/afichet/spectral-exr, EXRSpectralImage::getStokesChannelName): "S0." + the value
/// printed with 6 decimals and ',' as the decimal separator ('.' separates layers) + "nm", e.g.
/// 392.5 nm → "S0.392,500000nm".
std::string spectralChannelName(double centreNm);

/// A render's EXR with its layers (ZIP, float): R, G, B (linear sRGB); `bins` channels
/// spectralChannelName(bin centre) of [380, 780] nm cut in `bins` equal bins (spectral: bins per
/// pixel, pixel-major) with the string attribute emissiveUnits = "W.m^-2.sr^-1.nm^-1"; if
/// `modes` is not empty (6 floats per pixel), o.R, o.G, o.B, e.R, e.G, e.B (fast.R … slow.B with
/// `fast_slow`: a scene whose crystals are all biaxial); then the channels `extra_names` (e.g. the
/// AOV layer's Z, Px, …), from `extra`: extra_names.size() floats per pixel, pixel-major. For
/// writeFilesTogether.
FileContent exrLayersContent(int width, int height, const std::vector<float>& rgb, int bins,
                             const std::vector<float>& spectral, const std::vector<float>& modes,
                             const std::vector<std::string>& extra_names = {},
                             const std::vector<float>& extra = {}, bool fast_slow = false);

/// A polarised render's EXR (ZIP, float): R, G, B (= S0) and the Stokes layers named as Mitsuba
/// 3's Stokes film writes them, S0.R, S0.G, S0.B, S1.R, …, S3.B (`stokes`: 12 floats per pixel,
/// S0.RGB first), with the string attribute stokesFrame = `frame` (their reference frame). For
/// writeFilesTogether.
FileContent exrStokesContent(int width, int height, const std::vector<float>& rgb,
                             const std::vector<float>& stokes, const std::string& frame);

/// Write linear RGB floats (3 per pixel) as an EXR with R, G, B channels, atomically.
void writeExrRgb(const std::filesystem::path& path, int width, int height,
                 const std::vector<float>& rgb);

/// The tone-mapped 8-bit sRGB pixels (3 per pixel, rows from the top) of the PNG preview: what
/// `eikon view` shows on screen, byte for byte the preview `eikon render` writes.
std::vector<unsigned char> previewPixels(int width, int height, const std::vector<float>& rgb,
                                         double exposure = 0.0);

/// The 8-bit sRGB PNG preview of writePngPreview, for writeFilesTogether (pixels copied).
FileContent pngPreviewContent(int width, int height, const std::vector<float>& rgb,
                              double exposure = 0.0);

/// Write an 8-bit sRGB PNG preview of linear RGB (3 floats per pixel): multiply by 2^exposure,
/// Reinhard-style tone map x/(1+x) on luminance-preserving ratio, sRGB transfer. Atomic.
void writePngPreview(const std::filesystem::path& path, int width, int height,
                     const std::vector<float>& rgb, double exposure = 0.0);

}  // namespace eikon
