// A small RAII layer over the HDF5 C API for rbdem's writers (io/result_h5.cpp, io/checkpoint.cpp): every id is
// closed by its owner, every failure becomes an exception that names the file and the object. Files are built in
// memory and written with every write checked (a full disk is reported, never a truncated file).
#pragma once

#include <hdf5.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/results.hpp"

namespace rbdem::io::h5 {


class Id {
 public:
  Id() = default;
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  Id(Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  Id& operator=(Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      close_ = o.close_;
    }
    return *this;
  }
  ~Id() { reset(); }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: reads like the C API it wraps
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  // Closes now and reports whether HDF5 managed (closing a file writes its last metadata: a full disk shows here).
  bool close() {
    const bool good = id_ < 0 || !close_ || close_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return good;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

// Silences HDF5's error stack printing while probing (is this an HDF5 file? does this path exist?), where a "no"
// is an answer, not an error. Restores the previous handler.
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

[[noreturn]] inline void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error(fmt::format("HDF5: {} failed for {}", what, file));
}

// File and memory types of the element types we store.
template <class T>
struct H5Type;
template <>
struct H5Type<double> {
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct H5Type<float> {
  static hid_t file() { return H5T_IEEE_F32LE; }
  static hid_t mem() { return H5T_NATIVE_FLOAT; }
};
template <>
struct H5Type<std::int32_t> {
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t mem() { return H5T_NATIVE_INT32; }
};
static_assert(std::is_same_v<int, std::int32_t>, "mesh and bond indices (int) are stored as int32");
template <>
struct H5Type<std::uint8_t> {
  static hid_t file() { return H5T_STD_U8LE; }
  static hid_t mem() { return H5T_NATIVE_UINT8; }
};
template <>
struct H5Type<std::int64_t> {
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t mem() { return H5T_NATIVE_INT64; }
};

constexpr unsigned deflate_level = 4;
constexpr std::size_t compress_above_bytes = 4096;     // smaller datasets are stored contiguous
constexpr std::size_t chunk_target_bytes = 1u << 20;   // HDF5's default chunk cache is 1 MiB

// HDF5's shuffle filter on one chunk: byte k of every element, then byte k + 1, ... (H5Z_FILTER_SHUFFLE's layout).
inline void shuffle_bytes(const unsigned char* in, std::size_t bytes, std::size_t element, unsigned char* out) {
  const std::size_t n = bytes / element;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < element; ++k) out[k * n + i] = in[i * element + k];
}

class Writer {
 public:
  // `threads`: how many threads compress the datasets at save() (1: serially).
  explicit Writer(std::string file, int threads = 1) : file_(std::move(file)), threads_(std::max(threads, 1)) {}

  // The file is built in memory (HDF5's core driver, no backing store) and written by save(): HDF5 never meets a
  // full disk itself (after a failed write its library state is broken and it crashes at exit), and the bytes go
  // through write_file_checked, which reports a short write.
  Id create_file() const {
    Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    if (fapl < 0 || H5Pset_fapl_core(fapl, 1 << 20, 0) < 0) fail(file_, "setting up the in-memory file");
    Id f(H5Fcreate(file_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose);
    if (f < 0) fail(file_, "creating the file");
    return f;
  }

  // Closes the in-memory file and writes its image to disk, every write checked.
  void save(Id& file) const {
    write_pending();
    if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) fail(file_, "flushing the file");
    const ssize_t n = H5Fget_file_image(file, nullptr, 0);
    if (n < 0) fail(file_, "sizing the file image");
    std::string image(std::size_t(n), '\0');
    if (H5Fget_file_image(file, image.data(), image.size()) < 0) fail(file_, "copying the file image");
    if (!file.close()) fail(file_, "closing the file");
    write_file_checked(file_, image);
  }

  Id group(hid_t loc, const std::string& name) const {
    Id g(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (g < 0) fail(file_, "creating group " + name);
    return g;
  }

  // A dataset of `dims` (row-major) from `data`; chunked, shuffled and deflated when it is more than a few KB.
  template <class T>
  void dataset(hid_t loc, const std::string& name, const T* data, const std::vector<hsize_t>& dims) const {
    Id space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), H5Sclose);
    if (space < 0) fail(file_, "creating the dataspace of " + name);
    Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    hsize_t n = 1;
    for (const hsize_t d : dims) n *= d;
    const bool compress = n * sizeof(T) > compress_above_bytes;
    std::vector<hsize_t> chunk = dims;
    if (compress) {
      chunk[0] = std::clamp<hsize_t>(chunk_target_bytes / ((n / dims[0]) * sizeof(T)), 1, dims[0]);
      if (H5Pset_chunk(dcpl, int(chunk.size()), chunk.data()) < 0 || H5Pset_shuffle(dcpl) < 0 ||
          H5Pset_deflate(dcpl, deflate_level) < 0)
        fail(file_, "setting chunking and compression of " + name);
    }
    Id ds(H5Dcreate2(loc, name.c_str(), H5Type<T>::file(), space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose);
    if (ds < 0) fail(file_, "creating dataset " + name);
    if (compress) {
      // Compressed at save(), with the others, on the writer's threads (the element types stored are
      // little-endian in memory as in the file: x86-64).
      Pending p{std::move(ds), name, sizeof(T), dims.size(), dims[0], chunk[0], {}};
      p.bytes.resize(std::size_t(n) * sizeof(T));
      std::memcpy(p.bytes.data(), data, p.bytes.size());
      pending_.push_back(std::move(p));
      return;
    }
    if (n > 0 && H5Dwrite(ds, H5Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail(file_, "writing dataset " + name);
  }
  template <class T>
  void dataset(hid_t loc, const std::string& name, const std::vector<T>& v) const {
    dataset(loc, name, v.data(), {hsize_t(v.size())});
  }
  template <class T>
  void dataset(hid_t loc, const std::string& name, const std::vector<T>& v, hsize_t columns) const {
    dataset(loc, name, v.data(), {hsize_t(v.size() / columns), columns});
  }

  template <class T>
  void attribute(hid_t loc, const std::string& name, T value) const {
    Id space(H5Screate(H5S_SCALAR), H5Sclose);
    Id a(H5Acreate2(loc, name.c_str(), H5Type<T>::file(), space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (a < 0 || H5Awrite(a, H5Type<T>::mem(), &value) < 0) fail(file_, "writing attribute " + name);
  }

  // Variable-length UTF-8 strings: h5py reads them as str, and they have no size limit.
  void attribute(hid_t loc, const std::string& name, const std::string& value) const {
    attribute_strings(loc, name, {value}, true);
  }
  void attribute_strings(hid_t loc, const std::string& name, const std::vector<std::string>& values,
                         bool scalar = false) const {
    Id type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (type < 0 || H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0)
      fail(file_, "making the string type of attribute " + name);
    const hsize_t n = values.size();
    Id space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
    std::vector<const char*> p;
    for (const auto& s : values) p.push_back(s.c_str());
    Id a(H5Acreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (a < 0 || H5Awrite(a, type, p.data()) < 0) fail(file_, "writing attribute " + name);
  }

 private:
  // A chunked dataset waiting for its data: the bytes in row-major order, split into chunks along the first axis.
  struct Pending {
    Id ds;
    std::string name;
    std::size_t element = 0;  // bytes per value
    std::size_t rank = 0;
    hsize_t rows = 0, chunk_rows = 0;  // along the first axis: the dataset's and a chunk's
    std::vector<unsigned char> bytes;
  };

  // Shuffles and deflates every chunk of the pending datasets in parallel (no HDF5 call: zlib only), then stores
  // them in order with H5Dwrite_chunk: the bytes HDF5's own shuffle and deflate filters would have stored, the
  // last chunk of a dataset padded with the fill value 0 as HDF5 pads it.
  void write_pending() const {
    struct Job {
      std::size_t dataset, first_row, have;  // have: the chunk's bytes of data (less than a chunk at the end)
      std::string compressed;
    };
    std::vector<Job> jobs;
    for (std::size_t d = 0; d < pending_.size(); ++d) {
      const Pending& p = pending_[d];
      for (hsize_t r = 0; r < p.rows; r += p.chunk_rows)
        jobs.push_back({d, r, std::min<std::size_t>(p.chunk_rows, p.rows - r) * (p.bytes.size() / p.rows), {}});
    }
    // The largest chunks first, so that no thread is left compressing a big one while the others wait.
    std::vector<std::size_t> order(jobs.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return jobs[a].have > jobs[b].have; });
    std::atomic<bool> failed{false};
#pragma omp parallel for schedule(dynamic) num_threads(threads_) if (threads_ > 1 && jobs.size() > 1)
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t j = order[k];
      const Pending& p = pending_[jobs[j].dataset];
      const std::size_t row = p.bytes.size() / p.rows, bytes = p.chunk_rows * row, have = jobs[j].have;
      const unsigned char* in = p.bytes.data() + jobs[j].first_row * row;
      std::vector<unsigned char> padded, shuffled(bytes);
      if (have < bytes) {  // the last chunk, partial: padded with the fill value
        padded.assign(bytes, 0);
        std::memcpy(padded.data(), in, have);
        in = padded.data();
      }
      shuffle_bytes(in, bytes, p.element, shuffled.data());
      uLongf size = compressBound(uLong(shuffled.size()));
      std::string out(size, '\0');
      if (compress2(reinterpret_cast<Bytef*>(out.data()), &size, shuffled.data(), uLong(shuffled.size()),
                    int(deflate_level)) != Z_OK) {
        failed = true;
        continue;
      }
      out.resize(size);
      jobs[j].compressed = std::move(out);
    }
    if (failed) fail(file_, "compressing the datasets");
    for (const Job& job : jobs) {
      const Pending& p = pending_[job.dataset];
      std::vector<hsize_t> offset(p.rank, 0);
      offset[0] = job.first_row;
      if (H5Dwrite_chunk(p.ds, H5P_DEFAULT, 0, offset.data(), job.compressed.size(), job.compressed.data()) < 0)
        fail(file_, "writing dataset " + p.name);
    }
    pending_.clear();
  }

  std::string file_;
  int threads_ = 1;
  mutable std::vector<Pending> pending_;
};

// ---------------------------------------------------------------------------------------------------------------
// Reading.

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  Id open_file() const {
    bool is_hdf5 = false;
    {
      const QuietHdf5Errors quiet;
      is_hdf5 = H5Fis_hdf5(file_.c_str()) > 0;
    }
    if (!is_hdf5) fail(file_, "opening (missing, or not an HDF5 file)");
    Id f(H5Fopen(file_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (f < 0) fail(file_, "opening the file");
    return f;
  }

  Id group(hid_t loc, const std::string& name) const {
    if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) fail(file_, "finding group " + name + " (not a result.h5?)");
    Id g(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose);
    if (g < 0) fail(file_, "opening group " + name);
    return g;
  }

  template <class T>
  std::vector<T> dataset(hid_t loc, const std::string& name, std::vector<hsize_t>* dims_out = nullptr) const {
    if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) fail(file_, "finding dataset " + name);
    Id ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (ds < 0) fail(file_, "opening dataset " + name);
    Id space(H5Dget_space(ds), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space);
    if (rank < 0) fail(file_, "reading the shape of " + name);
    std::vector<hsize_t> dims(std::size_t(rank), 0);
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    hsize_t n = 1;
    for (const hsize_t d : dims) n *= d;
    std::vector<T> v(n);
    if (n > 0 && H5Dread(ds, H5Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
      fail(file_, "reading dataset " + name);
    if (dims_out) *dims_out = dims;
    return v;
  }

  template <class T>
  T attribute(hid_t loc, const std::string& name) const {
    Id a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
    T value{};
    if (a < 0 || H5Aread(a, H5Type<T>::mem(), &value) < 0) fail(file_, "reading attribute " + name);
    return value;
  }

  std::vector<std::string> attribute_strings(hid_t loc, const std::string& name) const {
    if (H5Aexists(loc, name.c_str()) <= 0) fail(file_, "finding attribute " + name);
    Id a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
    if (a < 0) fail(file_, "opening attribute " + name);
    Id ftype(H5Aget_type(a), H5Tclose);
    Id space(H5Aget_space(a), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    if (H5Tget_class(ftype) != H5T_STRING || n < 0) fail(file_, "reading attribute " + name + " (not a string)");
    std::vector<std::string> out;
    if (H5Tis_variable_str(ftype) > 0) {
      Id mtype(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mtype, H5T_VARIABLE);
      H5Tset_cset(mtype, H5Tget_cset(ftype));
      std::vector<char*> p(std::size_t(n), nullptr);
      if (H5Aread(a, mtype, p.data()) < 0) fail(file_, "reading attribute " + name);
      for (char* s : p) {
        out.emplace_back(s ? s : "");
        H5free_memory(s);
      }
    } else {  // fixed-length strings (as other tools may write them)
      const std::size_t size = H5Tget_size(ftype);
      std::vector<char> buf(size * std::size_t(n));
      if (H5Aread(a, ftype, buf.data()) < 0) fail(file_, "reading attribute " + name);
      for (hssize_t k = 0; k < n; ++k) {
        const char* s = buf.data() + std::size_t(k) * size;
        out.emplace_back(s, std::find(s, s + size, '\0'));
      }
    }
    return out;
  }
  std::string attribute_string(hid_t loc, const std::string& name) const {
    auto v = attribute_strings(loc, name);
    if (v.size() != 1) fail(file_, "reading attribute " + name + " (expected one string)");
    return v.front();
  }

 private:
  std::string file_;
};

// Debian's HDF5 is built without thread safety: every call into it, from any thread (sweeps write several runs at
// once), goes through this lock.
inline std::mutex& lock() {
  static std::mutex m;
  return m;
}

}  // namespace rbdem::io::h5
