// Mitsuba's serialized meshes (.serialized), read by hand: no packaged library reads
// them. The layout, as Mitsuba 3 documents it (its src/shapes/serialized.cpp, the
// plugin's "Format description"), all little-endian:
//
//   the file      shape, shape, ..., then the table: each shape's file offset
//                 (u64; u32 in version 3), then the shape count (u32)
//   a shape       u16 format identifier 0x041C, u16 version (3 or 4), then one
//                 zlib stream holding:
//                   u32 flags: 0x0001 vertex normals, 0x0002 UVs, 0x0008 vertex
//                       colours, 0x0010 face normals, 0x1000 single precision,
//                       0x2000 double precision
//                   version 4: the shape's name, UTF-8, NUL-terminated
//                   u64 vertex count, u64 triangle count
//                   positions (xyz), normals (xyz), UVs (uv), colours (rgb): one
//                       array each, where flagged, of floats or doubles
//                   triangles: three u32 vertex indices each (u64 where the vertex
//                       count passes 2^32 - 1, which wavetrace cannot hold)
//
// As Mitsuba does, shape 0 is read from the file's start without the table, and
// another shape from where the table says. Every count and offset is checked against
// the file before it is used, and the data is inflated as it is read, so a file's
// counts never allocate more than its stream holds. The inflated stream must hold
// exactly what its counts say.
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>

#include "errors/errors.hpp"
#include "scene/mesh_formats.hpp"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the serialized reader copies little-endian numbers as they are");

namespace wt {

namespace {

constexpr uint16_t kFormat = 0x041C;
constexpr uint32_t kHasNormals = 0x0001, kHasUvs = 0x0002, kHasColours = 0x0008, kFaceNormals = 0x0010,
                   kSingle = 0x1000, kDouble = 0x2000;
// The longest shape name read (a stream that never ends its name is refused here).
constexpr size_t kMaxName = size_t{1} << 20;
// Deflate inflates at most 1032 to 1 (zlib's FAQ): a shape's counts that need more
// than this of its compressed bytes are false, whatever the stream holds.
constexpr uint64_t kMostInflation = 1032;

template <class T>
T read_at(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string hex(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", v);
  return buf;
}

// One shape's zlib stream, inflated on demand into `out`: never more than asked for.
class Inflater {
 public:
  Inflater(const char* in, size_t size, std::string prefix) : prefix_(std::move(prefix)), in_(in), left_(size) {
    if (inflateInit(&z_) != Z_OK) throw InputError(prefix_ + "cannot start zlib");
  }
  ~Inflater() { inflateEnd(&z_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  std::string out;

  // Inflates until `out` holds n bytes; false where the stream ends first.
  bool fill(size_t n) {
    constexpr size_t kStep = size_t{64} << 20;
    while (out.size() < n && !ended_) {
      const size_t have = out.size(), want = std::min(n - have, kStep);
      out.resize(have + want);
      const size_t made = step(&out[have], want);
      out.resize(have + made);
    }
    return out.size() >= n;
  }

  // Whether the stream ends where `out` does (nothing more to inflate; fill may
  // have inflated more than a later need, which the caller compares).
  bool ends_here() {
    char extra;
    while (!ended_) {
      if (step(&extra, 1) != 0) return false;
    }
    return true;
  }

 private:
  // Inflates into [dst, dst + cap) until something comes out or the stream ends;
  // returns how many bytes came out. A corrupt stream or one that the file cuts
  // short is an error.
  size_t step(char* dst, size_t cap) {
    z_.next_out = reinterpret_cast<Bytef*>(dst);
    z_.avail_out = static_cast<uInt>(std::min<size_t>(cap, std::numeric_limits<uInt>::max()));
    const uInt asked = z_.avail_out;
    for (;;) {
      if (z_.avail_in == 0 && left_ > 0) {
        const size_t chunk = std::min<size_t>(left_, uInt{1} << 30);
        z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in_));
        z_.avail_in = static_cast<uInt>(chunk);
        in_ += chunk;
        left_ -= chunk;
      }
      const uInt before_in = z_.avail_in;
      const int rc = inflate(&z_, Z_NO_FLUSH);
      const size_t made = asked - z_.avail_out;
      if (rc == Z_STREAM_END) {
        ended_ = true;
        return made;
      }
      if (rc == Z_NEED_DICT || rc == Z_DATA_ERROR || rc == Z_MEM_ERROR || rc == Z_STREAM_ERROR) {
        throw InputError(prefix_ + "corrupt zlib stream (" + (z_.msg ? z_.msg : zError(rc)) + ")");
      }
      if (made > 0) return made;
      if (z_.avail_in == 0 && left_ == 0) throw InputError(prefix_ + "the zlib stream is cut short (the file ends inside it)");
      if (rc == Z_BUF_ERROR && z_.avail_in == before_in) {
        throw InputError(prefix_ + "the zlib stream makes no progress");
      }
    }
  }

  std::string prefix_;
  z_stream z_{};
  const char* in_;
  size_t left_;
  bool ended_ = false;
};

}  // namespace

void load_serialized(const std::string& bytes, uint32_t shape_index, TriangleMesh& mesh) {
  const std::string& path = mesh.source;
  auto fail = [&](const std::string& what) { throw InputError(path + ": " + what); };
  const std::string bad = "malformed serialized mesh: ";
  const uint64_t size = bytes.size();
  if (size == 0) fail(bad + "the file is empty");
  if (size < 4) fail(bad + "the file is " + std::to_string(size) + " bytes, too short for a shape's header");
  const char* data = bytes.data();
  const uint16_t format = read_at<uint16_t>(data), version = read_at<uint16_t>(data + 2);
  if (format != kFormat) {
    fail("not a Mitsuba serialized mesh (format identifier " + hex(format) + ", expected 0x041C)");
  }
  if (version != 3 && version != 4) {
    fail("serialized mesh version " + std::to_string(version) + " is not supported (versions 3 and 4 are read)");
  }

  // Where the shape starts, and where its bytes end (the table's start, where read).
  uint64_t offset = 0, end = size;
  if (shape_index > 0) {
    if (size < 8) fail(bad + "the file is too short to hold the table of its shapes");
    const uint32_t count = read_at<uint32_t>(data + size - 4);
    if (shape_index >= count) {
      fail("shape_index " + std::to_string(shape_index) + " is past the file's " + std::to_string(count) +
           (count == 1 ? " shape" : " shapes"));
    }
    const uint64_t entry = version == 4 ? 8 : 4;
    const uint64_t table = uint64_t{count} * entry + 4;
    if (table > size - 4) {
      fail(bad + "its table of " + std::to_string(count) + " shapes (" + std::to_string(table) +
           " bytes) does not fit in the file (" + std::to_string(size) + " bytes)");
    }
    end = size - table;
    const char* at = data + end + uint64_t{shape_index} * entry;
    offset = version == 4 ? read_at<uint64_t>(at) : read_at<uint32_t>(at);
    if (offset > end || end - offset < 4) {
      fail(bad + "shape " + std::to_string(shape_index) + "'s offset " + std::to_string(offset) +
           " is not within the shapes' " + std::to_string(end) + " bytes");
    }
    if (read_at<uint16_t>(data + offset) != kFormat || read_at<uint16_t>(data + offset + 2) != version) {
      fail(bad + "shape " + std::to_string(shape_index) + "'s offset " + std::to_string(offset) +
           " does not point at a shape's header (format 0x041C, version " + std::to_string(version) + ")");
    }
  }

  const std::string where = bad + "shape " + std::to_string(shape_index) + ": ";
  const uint64_t compressed = end - offset - 4;
  Inflater z(data + offset + 4, compressed, path + ": " + where);
  const std::string& out = z.out;
  auto short_header = [&] { fail(where + "the inflated shape ends inside its header (" + std::to_string(out.size()) + " bytes)"); };

  if (!z.fill(4)) short_header();
  const uint32_t flags = read_at<uint32_t>(out.data());
  size_t at = 4;
  if (version == 4) {  // the name, not kept
    size_t nul;
    while ((nul = out.find('\0', 4)) == std::string::npos) {
      if (out.size() - 4 > kMaxName) fail(where + "its name is not ended within " + std::to_string(kMaxName) + " bytes");
      if (!z.fill(out.size() + 256) && out.find('\0', 4) == std::string::npos) short_header();
    }
    at = nul + 1;
  }
  if (!z.fill(at + 16)) short_header();
  const uint64_t vertices = read_at<uint64_t>(out.data() + at), triangles = read_at<uint64_t>(out.data() + at + 8);
  at += 16;
  if ((flags & kSingle) && (flags & kDouble)) fail(where + "flags " + hex(flags) + " give both single and double precision");
  if (vertices > std::numeric_limits<uint32_t>::max()) {
    fail(where + std::to_string(vertices) + " vertices: more than 2^32 - 1");
  }

  // What its counts say the stream holds, checked against what the stream can hold.
  const bool double_precision = flags & kDouble;
  const bool normals = flags & kHasNormals, uvs = flags & kHasUvs, colours = flags & kHasColours;
  const uint64_t real = double_precision ? 8 : 4;
  const uint64_t per_vertex = real * (3 + (normals ? 3 : 0) + (uvs ? 2 : 0) + (colours ? 3 : 0));
  const uint64_t vertex_bytes = vertices * per_vertex;
  const uint64_t most = std::numeric_limits<uint64_t>::max();
  auto counts = [&] {
    return std::to_string(vertices) + " vertices and " + std::to_string(triangles) + " triangles";
  };
  if (triangles > (most - at - vertex_bytes) / 12 ||
      at + vertex_bytes + 12 * triangles > kMostInflation * compressed + 1024) {
    fail(where + "its counts (" + counts() + ") need more bytes than its " + std::to_string(compressed) +
         " compressed bytes can hold");
  }
  const uint64_t total = at + vertex_bytes + 12 * triangles;
  if (!z.fill(total)) {
    fail(where + "its counts (" + counts() + ") need " + std::to_string(total) + " inflated bytes, but it holds " +
         std::to_string(out.size()));
  }
  if (out.size() > total || !z.ends_here()) {
    fail(where + "it holds more than the " + std::to_string(total) + " inflated bytes its counts (" + counts() +
         ") need");
  }

  IndexedMesh m;
  const size_t n = vertices;
  const char* p = out.data() + at;
  // The k-th number of the array at p, as a float (a double beyond float's range
  // becomes an infinity: a position's drops its triangles, a normal's is an error).
  auto real_at = [&](size_t k) {
    return double_precision ? static_cast<float>(read_at<double>(p + 8 * k)) : read_at<float>(p + 4 * k);
  };
  m.positions.resize(n);
  for (size_t i = 0; i < n; ++i) m.positions[i] = vec3(real_at(3 * i), real_at(3 * i + 1), real_at(3 * i + 2));
  p += n * 3 * real;
  // Mitsuba's face-normals flag: the shape is drawn faceted, its vertex normals
  // (read past) unused.
  if (normals) {
    if (!(flags & kFaceNormals)) {
      m.normals.resize(n);
      for (size_t i = 0; i < n; ++i) m.normals[i] = vec3(real_at(3 * i), real_at(3 * i + 1), real_at(3 * i + 2));
    }
    p += n * 3 * real;
  }
  // Mitsuba reads a serialized shape's UVs as they are (unlike an OBJ's, whose v it
  // flips): its v = 0, like a mesh's here, is the image's top row.
  if (uvs) {
    m.uvs.resize(n);
    for (size_t i = 0; i < n; ++i) m.uvs[i] = vec2(real_at(2 * i), real_at(2 * i + 1));
    p += n * 2 * real;
  }
  if (colours) p += n * 3 * real;  // read, not rendered
  m.triangles.resize(triangles);
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t index = read_at<uint32_t>(p + 4 * (3 * t + k));
      if (index >= n) {
        fail(where + "triangle " + std::to_string(t) + ": vertex index " + std::to_string(index) +
             " is out of range (" + std::to_string(n) + " vertices)");
      }
      m.triangles[t][k] = index;
    }
  }
  add_indexed_mesh(m, mesh);
}

}  // namespace wt
