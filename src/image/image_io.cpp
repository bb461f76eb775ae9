#include "image/image_io.hpp"

#include <stb/stb_image_write.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "wavetrace/film.hpp"

namespace wt {

namespace fs = std::filesystem;

namespace {

enum class Format { Png, Pfm };

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Format format_of(const std::string& path) {
  std::string ext = lower_extension(path);
  if (ext == ".png") return Format::Png;
  if (ext == ".pfm") return Format::Pfm;
  throw OutputError(path + ": unknown output format '" + ext + "' (use .png or .pfm)");
}

fs::path folder_of(const std::string& path) {
  fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

std::string temporary_name(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

// Renames tmp over path, or removes tmp and throws.
void commit(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp);
    throw OutputError(path + ": cannot write (" + ec.message() + ")");
  }
}

void write_png(const std::string& tmp, const std::string& path, int w, int h, const std::vector<float>& rgb,
               Encoding encoding) {
  std::vector<unsigned char> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    float v = encoding == Encoding::Srgb ? encode_srgb(rgb[i]) : encode_gamma2(rgb[i]);
    bytes[i] = static_cast<unsigned char>(std::lround(v * 255.0f));
  }
  if (!stbi_write_png(tmp.c_str(), w, h, 3, bytes.data(), w * 3)) {
    fs::remove(tmp);
    throw OutputError(path + ": cannot write PNG");
  }
}

// PFM: a text header, then little-endian floats, bottom row first.
void write_pfm(const std::string& tmp, const std::string& path, int w, int h, const std::vector<float>& rgb) {
  std::ofstream f(tmp, std::ios::binary);
  f << "PF\n" << w << " " << h << "\n-1.0\n";
  for (int y = h - 1; y >= 0; --y) {
    f.write(reinterpret_cast<const char*>(rgb.data() + static_cast<size_t>(y) * w * 3),
            static_cast<std::streamsize>(sizeof(float) * w * 3));
  }
  f.close();
  if (!f) {
    fs::remove(tmp);
    throw OutputError(path + ": cannot write PFM");
  }
}

}  // namespace

void check_output_path(const std::string& path) {
  format_of(path);
  check_output_folder(path);
}

void check_output_folder(const std::string& path) {
  fs::path folder = folder_of(path);
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw OutputError(path + ": cannot write: folder '" + folder.string() + "' does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw OutputError(path + ": cannot write: folder '" + folder.string() + "' is not writable (" +
                      std::strerror(errno) + ")");
  }
  if (fs::is_directory(path, ec)) throw OutputError(path + ": cannot write: it is a folder");
}

void write_image(const std::string& path, int width, int height, const std::vector<float>& rgb, Encoding encoding) {
  Format format = format_of(path);
  std::string tmp = temporary_name(path);
  if (format == Format::Png) {
    write_png(tmp, path, width, height, rgb, encoding);
  } else {
    write_pfm(tmp, path, width, height, rgb);
  }
  commit(tmp, path);
}

void write_text_file(const std::string& path, const std::string& text) {
  std::string tmp = temporary_name(path);
  {
    std::ofstream f(tmp);
    f << text;
    f.close();
    if (!f) {
      fs::remove(tmp);
      throw OutputError(path + ": cannot write");
    }
  }
  commit(tmp, path);
}

}  // namespace wt
