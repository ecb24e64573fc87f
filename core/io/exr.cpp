#include "core/io/exr.h"

#include <ImfChannelList.h>
#include <ImfCheckFile.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/io/text_file.h"

namespace eikon {

RgbaImage readExrRgba(const std::filesystem::path& path, int max_width, int max_height) {
  const std::string p = path.string();
  std::error_code ec;  // is_regular_file without it throws for a name too long
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("'" + shownPath(path) +
                             "': " + (ec ? errorReason(ec) : std::string("not a regular file")));
  bool tiled = false, deep = false, multipart = false;
  if (!Imf::isOpenExrFile(p.c_str(), tiled, deep, multipart))
    throw std::runtime_error("'" + p + "' is not an OpenEXR file");
  if (deep)
    throw std::runtime_error("'" + p + "' is a deep EXR image; deep images are not supported");
  // checkOpenEXRFile returns true when it found a problem.
  if (Imf::checkOpenEXRFile(p.c_str(), /*reduceMemory=*/true, /*reduceTime=*/true))
    throw std::runtime_error("'" + p +
                             "' failed the OpenEXR integrity check (corrupt or unsafe file)");
  try {
    Imf::InputFile file(p.c_str());
    const auto dw = file.header().dataWindow();
    long w = long(dw.max.x) - dw.min.x + 1, h = long(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > max_width || h > max_height)
      throw std::runtime_error("'" + p + "': image size " + std::to_string(w) + "x" +
                               std::to_string(h) + " outside the accepted 1.." +
                               std::to_string(max_width) + " x 1.." + std::to_string(max_height));
    const auto& ch = file.header().channels();
    if (!ch.findChannel("R") || !ch.findChannel("G") || !ch.findChannel("B"))
      throw std::runtime_error("'" + p + "': expected R, G and B channels");
    RgbaImage img;
    img.width = int(w);
    img.height = int(h);
    img.rgba.assign(size_t(w * h * 4), 1.0f);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(img.rgba.data()) -
                 (long(dw.min.x) + long(dw.min.y) * w) * 4 * long(sizeof(float));
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 4 * sizeof(float),
                                     size_t(4 * w) * sizeof(float), 1, 1, c == 3 ? 1.0 : 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    for (size_t i = 0; i < img.rgba.size(); ++i)
      if (!std::isfinite(img.rgba[i]))
        throw std::runtime_error("'" + p + "' contains NaN or infinite pixels: pixel (" +
                                 std::to_string(i / 4 % size_t(w)) + ", " +
                                 std::to_string(i / 4 / size_t(w)) + ") channel " + "RGBA"[i % 4] +
                                 " is " + (std::isnan(img.rgba[i]) ? "NaN" : "infinite"));
    return img;
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + p + "': " + e.what());
  }
}

namespace {

void encodeExr(const std::filesystem::path& file, int width, int height,
               const std::vector<ExrChannel>& channels,
               const std::vector<std::pair<std::string, std::string>>& attributes = {}) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
  for (const auto& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
  Imf::FrameBuffer fb;
  for (const auto& c : channels)
    fb.insert(c.name,
              Imf::Slice(Imf::FLOAT, (char*)c.data, sizeof(float), size_t(width) * sizeof(float)));
  Imf::OutputFile out(file.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(height);
}

// libpng reports through callbacks; its defaults print "libpng error: ..." / "libpng warning: ..."
// on stderr themselves. These keep the message (and errno, for I/O failures) so that eikon prints
// its one line, and drop warnings (none can arise for the 8-bit RGB images written here).
struct PngErrorState {
  char message[256] = "";
  int err = 0;
};

void pngError(png_structp png, png_const_charp msg) {
  auto* st = static_cast<PngErrorState*>(png_get_error_ptr(png));
  st->err = errno;
  std::snprintf(st->message, sizeof st->message, "%s", msg ? msg : "unknown error");
  png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

void encodePng(const std::filesystem::path& file, int width, int height,
               const std::vector<unsigned char>& px) {
  FILE* f = std::fopen(file.c_str(), "wb");
  if (!f)
    throw std::runtime_error(std::string("cannot open a temporary file: ") + std::strerror(errno));
  PngErrorState st;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &st, pngError, pngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  // Only plain C state lives between setjmp and a longjmp back here (no destructors skipped).
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    std::string why = std::string("libpng: ") + (st.message[0] ? st.message : "cannot allocate");
    if (st.err != 0) why += std::string(" (") + std::strerror(st.err) + ")";
    throw std::runtime_error(why);
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) png_write_row(png, &px[size_t(y) * size_t(width) * 3]);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) throw std::runtime_error(std::strerror(errno));
}

}  // namespace

void writeExr(const std::filesystem::path& path, int width, int height,
              const std::vector<ExrChannel>& channels) {
  writeFileAtomically(
      path, [&](const std::filesystem::path& tmp) { encodeExr(tmp, width, height, channels); });
}

FileContent exrRgbContent(int width, int height, const std::vector<float>& rgb) {
  size_t n = size_t(width) * size_t(height);
  if (rgb.size() != 3 * n) throw std::invalid_argument("exrRgbContent: pixel count mismatch");
  auto planes = std::make_shared<std::array<std::vector<float>, 3>>();
  for (auto& p : *planes) p.resize(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) (*planes)[c][i] = rgb[3 * i + c];
  return [planes, width, height](const std::filesystem::path& tmp) {
    encodeExr(tmp, width, height,
              {{"R", (*planes)[0].data()}, {"G", (*planes)[1].data()}, {"B", (*planes)[2].data()}});
  };
}

std::string spectralChannelName(double centreNm) {
  std::string v = std::to_string(centreNm);  // "%f": 6 decimals, '.' in the C locale
  std::replace(v.begin(), v.end(), '.', ',');
  return "S0." + v + "nm";
}

FileContent exrLayersContent(int width, int height, const std::vector<float>& rgb, int bins,
                             const std::vector<float>& spectral, const std::vector<float>& modes,
                             const std::vector<std::string>& extra_names,
                             const std::vector<float>& extra, bool fast_slow) {
  const size_t n = size_t(width) * size_t(height);
  if (rgb.size() != 3 * n || spectral.size() != size_t(std::max(bins, 0)) * n ||
      (!modes.empty() && modes.size() != 6 * n) || extra.size() != extra_names.size() * n)
    throw std::invalid_argument("exrLayersContent: pixel count mismatch");
  // One plane per channel: R, G, B, then the bins, then o.R … e.B, then the extra channels.
  std::vector<std::string> names = {"R", "G", "B"};
  const double width_nm = bins > 0 ? 400.0 / bins : 0.0;
  for (int k = 0; k < bins; ++k) names.push_back(spectralChannelName(380.0 + (k + 0.5) * width_nm));
  if (!modes.empty())
    for (const char* m : {fast_slow ? "fast." : "o.", fast_slow ? "slow." : "e."})
      for (const char* c : {"R", "G", "B"}) names.push_back(std::string(m) + c);
  const size_t extraAt = names.size(), E = extra_names.size();
  names.insert(names.end(), extra_names.begin(), extra_names.end());
  auto planes =
      std::make_shared<std::vector<std::vector<float>>>(names.size(), std::vector<float>(n));
  for (size_t i = 0; i < n; ++i) {
    for (size_t c = 0; c < 3; ++c) (*planes)[c][i] = rgb[3 * i + c];
    for (size_t k = 0; k < size_t(std::max(bins, 0)); ++k)
      (*planes)[3 + k][i] = spectral[i * size_t(bins) + k];
    if (!modes.empty())
      for (size_t c = 0; c < 6; ++c)
        (*planes)[3 + size_t(std::max(bins, 0)) + c][i] = modes[6 * i + c];
    for (size_t c = 0; c < E; ++c) (*planes)[extraAt + c][i] = extra[E * i + c];
  }
  std::vector<std::pair<std::string, std::string>> attributes;
  if (bins > 0) {
    // Fichet et al. 2021's emissive spectral layout: S0 channels in ascending wavelength, their
    // unit in a string attribute; each channel is the bin's mean spectral radiance.
    attributes.push_back({"emissiveUnits", "W.m^-2.sr^-1.nm^-1"});
    attributes.push_back({"spectralBins", std::to_string(bins) + " bins of " +
                                              std::to_string(width_nm) +
                                              " nm over 380-780 nm, named by their centres"});
  }
  return [planes, names, attributes, width, height](const std::filesystem::path& tmp) {
    std::vector<ExrChannel> channels;
    for (size_t c = 0; c < names.size(); ++c) channels.push_back({names[c], (*planes)[c].data()});
    encodeExr(tmp, width, height, channels, attributes);
  };
}

FileContent exrStokesContent(int width, int height, const std::vector<float>& rgb,
                             const std::vector<float>& stokes, const std::string& frame) {
  const size_t n = size_t(width) * size_t(height);
  if (rgb.size() != 3 * n || stokes.size() != 12 * n)
    throw std::invalid_argument("exrStokesContent: pixel count mismatch");
  std::vector<std::string> names = {"R", "G", "B"};
  for (const char* l : {"S0.", "S1.", "S2.", "S3."})
    for (const char* c : {"R", "G", "B"}) names.push_back(std::string(l) + c);
  auto planes =
      std::make_shared<std::vector<std::vector<float>>>(names.size(), std::vector<float>(n));
  for (size_t i = 0; i < n; ++i) {
    for (size_t c = 0; c < 3; ++c) (*planes)[c][i] = rgb[3 * i + c];
    for (size_t c = 0; c < 12; ++c) (*planes)[3 + c][i] = stokes[12 * i + c];
  }
  const std::vector<std::pair<std::string, std::string>> attributes = {{"stokesFrame", frame}};
  return [planes, names, attributes, width, height](const std::filesystem::path& tmp) {
    std::vector<ExrChannel> channels;
    for (size_t c = 0; c < names.size(); ++c) channels.push_back({names[c], (*planes)[c].data()});
    encodeExr(tmp, width, height, channels, attributes);
  };
}

void writeExrRgb(const std::filesystem::path& path, int width, int height,
                 const std::vector<float>& rgb) {
  writeFileAtomically(path, exrRgbContent(width, height, rgb));
}

std::vector<unsigned char> previewPixels(int width, int height, const std::vector<float>& rgb,
                                         double exposure) {
  size_t n = size_t(width) * size_t(height);
  if (rgb.size() != 3 * n) throw std::invalid_argument("previewPixels: pixel count mismatch");
  std::vector<unsigned char> px(3 * n);
  const double scale = std::pow(2.0, exposure);
  auto encode = [](double v) {
    v = std::clamp(v, 0.0, 1.0);
    double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return (unsigned char)std::lround(s * 255.0);
  };
  for (size_t i = 0; i < n; ++i) {
    double r = rgb[3 * i] * scale, g = rgb[3 * i + 1] * scale, b = rgb[3 * i + 2] * scale;
    double lum = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    double k = lum > 0 ? (lum / (1.0 + lum / 4.0)) / lum : 1.0;  // soft shoulder above ~1
    px[3 * i] = encode(r * k);
    px[3 * i + 1] = encode(g * k);
    px[3 * i + 2] = encode(b * k);
  }
  return px;
}

FileContent pngPreviewContent(int width, int height, const std::vector<float>& rgb,
                              double exposure) {
  size_t n = size_t(width) * size_t(height);
  if (rgb.size() != 3 * n) throw std::invalid_argument("pngPreviewContent: pixel count mismatch");
  auto px =
      std::make_shared<std::vector<unsigned char>>(previewPixels(width, height, rgb, exposure));
  return
      [px, width, height](const std::filesystem::path& tmp) { encodePng(tmp, width, height, *px); };
}

void writePngPreview(const std::filesystem::path& path, int width, int height,
                     const std::vector<float>& rgb, double exposure) {
  writeFileAtomically(path, pngPreviewContent(width, height, rgb, exposure));
}

}  // namespace eikon
