// Result files of a UCS run: result.h5 reproduces what the run produced, result.xdmf is well-formed and points at
// datasets that exist with the shapes it claims, a failed write leaves nothing under the final name, and the
// figure script draws every figure of a real run.
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "dem/record_columns.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/driver/driver.hpp"
#include "io/checkpoint.hpp"
#include "io/h5.hpp"
#include "io/result_h5.hpp"
#include "io/results.hpp"
#include "io/run_case.hpp"

namespace rbdem {
namespace {

namespace fs = std::filesystem;

// A small UCS run (about 800 blocks, a fraction of a second) written by io::run_case into a folder of its own
// (tests may run in parallel processes).
struct SmallRun {
  Scene scene;
  TriMesh mesh;
  Specimen specimen;
  TestResult result;
  fs::path dir;
};

// Removes a test's folder when the test passed (kept for inspection when it failed).
struct RemoveWhenPassed {
  fs::path dir;
  ~RemoveWhenPassed() {
    std::error_code ec;
    if (!testing::Test::HasFailure()) fs::remove_all(dir, ec);
  }
};

SmallRun small_run() {
  SmallRun r;
  r.scene.mesh.size = 0.004;
  r.scene.numerics.threads = 1;
  r.scene.numerics.elastic_start = true;
  r.mesh = make_mesh(r.scene);
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  r.dir = fs::temp_directory_path() / ("rbdem_test_io_" + std::string(info->name()) + "_" + std::to_string(getpid()));
  fs::remove_all(r.dir);
  io::CaseOptions co;
  co.out = r.dir;
  io::CaseRun run = io::run_case("ucs", r.scene, co);
  r.result = std::move(run.result), r.specimen = std::move(run.specimen);
  return r;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Equal as stored: bit for bit, NaN equal to NaN.
bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
template <class V>
bool same(const V& a, const V& b) {
  return a == b;
}

// Two tables of records equal in every stored field of their field table (dem/records.hpp).
template <class Record>
void expect_same_rows(const std::vector<Record>& a, const std::vector<Record>& b, int dim) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    Record::fields(dim, [&](const Field& f, auto get) {
      if constexpr (stored_field<decltype(get), Record>) {
        EXPECT_TRUE(same(get(a[k]), get(b[k]))) << f.name << ", row " << k;
      }
    });
}

TEST(Io, Hdf5RoundTripReproducesCurveAndCrackLog) {
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  const TestResult& r = run.result;
  ASSERT_FALSE(r.cracks.empty()) << "the test run should break bonds";
  ASSERT_GE(r.frames.size(), 3u);
  EXPECT_TRUE(fs::exists(run.dir / "result.h5"));
  EXPECT_FALSE(fs::exists(run.dir / "result.h5.tmp"));

  const io::StoredRun s = io::read_result_h5(run.dir / "result.h5");

  // Every stored field of every record, as the field tables list them (dem/records.hpp).
  expect_same_rows(r.curve, s.curve, 2);
  expect_same_rows(r.cracks, s.cracks, 2);
  ASSERT_EQ(s.frames.size(), r.frames.size());
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    SCOPED_TRACE(testing::Message() << "frame " << k);
    expect_same_rows(std::vector<Frame>{r.frames[k]}, std::vector<Frame>{s.frames[k]}, 2);
    EXPECT_EQ(s.frames[k].pose, r.frames[k].pose);
  }
  EXPECT_EQ(s.frames.back().label, "final");

  std::vector<double> nodes;
  for (const auto& p : run.mesh.nodes) nodes.insert(nodes.end(), {p[0], p[1]});
  std::vector<int> cells;
  for (const auto& t : run.mesh.triangles) cells.insert(cells.end(), {t[0], t[1], t[2]});
  EXPECT_EQ(s.dim, 2);
  EXPECT_EQ(s.nodes, nodes);
  EXPECT_EQ(s.cells, cells);
  EXPECT_EQ(s.layer, run.mesh.layer);
  EXPECT_EQ(s.layer_names, run.mesh.layer_names);
  EXPECT_EQ(s.scene_toml, to_toml(run.scene));
  EXPECT_EQ(nlohmann::json::parse(s.scene_json), scene_json(run.scene));
  // The summary attribute is summary.json.
  EXPECT_EQ(nlohmann::json::parse(s.summary_json), nlohmann::json::parse(read_text(run.dir / "summary.json")));

  // The bonds' breakage record agrees with the crack log; the shapes match the layout.
  const auto h5 = run.dir / "result.h5";
  const std::uint64_t T = run.specimen.num_blocks(), B = run.specimen.num_bonds();
  EXPECT_EQ(io::h5_dataset_shape(h5, "/bonds/break_mode"), (std::vector<std::uint64_t>{B}));
  EXPECT_EQ(io::h5_dataset_shape(h5, "/bonds/midpoint"), (std::vector<std::uint64_t>{B, 2}));
  EXPECT_EQ(io::h5_dataset_shape(h5, "/frames/00000/vertices"), (std::vector<std::uint64_t>{3 * T, 3}));
  EXPECT_EQ(io::h5_dataset_shape(h5, "/mesh/block_connectivity"), (std::vector<std::uint64_t>{T, 3}));
  EXPECT_FALSE(io::h5_dataset_shape(h5, "/frames/99999/vertices").has_value());
  EXPECT_FALSE(io::h5_dataset_shape(h5, "/frames").has_value());  // a group, not a dataset
}

// The writer compresses the chunks itself, on several threads, and stores them with H5Dwrite_chunk: HDF5 must read
// them back through its own shuffle and deflate filters exactly, for a dataset of several chunks whose last chunk
// is partial, and the stored chunks must not depend on the thread count.
TEST(Io, Hdf5ChunksCompressedInParallelReadBackExactly) {
  const fs::path dir = fs::temp_directory_path() / ("rbdem_test_io_chunks_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const RemoveWhenPassed cleanup{dir};
  // 3 columns of doubles: 43 690 rows per 1 MiB chunk, so 100 000 rows make two full chunks and a partial one.
  const hsize_t rows = 100000, cols = 3;
  std::vector<double> values(rows * cols);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = std::sin(0.001 * double(k)) * 1e-3 + double(k % 7);
  std::vector<std::int32_t> small{1, 2, 3};  // below the compression threshold: stored contiguous
  for (int threads : {1, 2}) {
    const std::string file = (dir / ("t" + std::to_string(threads) + ".h5")).string();
    const io::h5::Writer w(file, threads);
    io::h5::Id f = w.create_file();
    w.dataset(f, "values", values.data(), {rows, cols});
    w.dataset(f, "small", small);
    w.save(f);
  }
  for (int threads : {1, 2}) {
    SCOPED_TRACE(testing::Message() << threads << " threads");
    const io::h5::Reader r((dir / ("t" + std::to_string(threads) + ".h5")).string());
    const io::h5::Id f = r.open_file();
    std::vector<hsize_t> dims;
    EXPECT_EQ(r.dataset<double>(f, "values", &dims), values);
    EXPECT_EQ(dims, (std::vector<hsize_t>{rows, cols}));
    EXPECT_EQ(r.dataset<std::int32_t>(f, "small"), small);
    // The dataset declares the two filters its chunks went through, in HDF5's order.
    const io::h5::Id ds(H5Dopen2(f, "values", H5P_DEFAULT), H5Dclose);
    const io::h5::Id dcpl(H5Dget_create_plist(ds), H5Pclose);
    ASSERT_EQ(H5Pget_nfilters(dcpl), 2);
    unsigned flags = 0, values_of[4] = {0, 0, 0, 0};
    std::size_t n = 4;
    EXPECT_EQ(H5Pget_filter2(dcpl, 0, &flags, &n, values_of, 0, nullptr, nullptr), H5Z_FILTER_SHUFFLE);
    n = 4;
    EXPECT_EQ(H5Pget_filter2(dcpl, 1, &flags, &n, values_of, 0, nullptr, nullptr), H5Z_FILTER_DEFLATE);
    EXPECT_EQ(values_of[0], io::h5::deflate_level);
    hsize_t chunk[2] = {0, 0};
    ASSERT_EQ(H5Pget_chunk(dcpl, 2, chunk), 2);
    EXPECT_EQ(chunk[0], (1u << 20) / (cols * sizeof(double)));
    EXPECT_LT(fs::file_size(dir / ("t" + std::to_string(threads) + ".h5")), values.size() * sizeof(double));
  }
  // The stored (compressed) chunks are the same bytes at 1 and 2 threads. (The files as a whole differ in the
  // objects' modification times when the two writes straddle a second.)
  std::vector<std::vector<std::string>> stored;
  for (int threads : {1, 2}) {
    const io::h5::Reader r((dir / ("t" + std::to_string(threads) + ".h5")).string());
    const io::h5::Id f = r.open_file();
    const io::h5::Id ds(H5Dopen2(f, "values", H5P_DEFAULT), H5Dclose);
    std::vector<std::string> chunks;
    for (hsize_t row = 0; row < rows; row += (1u << 20) / (cols * sizeof(double))) {
      const hsize_t offset[2] = {row, 0};
      hsize_t bytes = 0;
      ASSERT_GE(H5Dget_chunk_storage_size(ds, offset, &bytes), 0);
      std::string chunk(bytes, '\0');
      uint32_t mask = 0;
      ASSERT_GE(H5Dread_chunk(ds, H5P_DEFAULT, offset, &mask, chunk.data()), 0);
      EXPECT_EQ(mask, 0u) << "every filter applied to the chunk at row " << row;
      chunks.push_back(std::move(chunk));
    }
    EXPECT_EQ(chunks.size(), 3u);
    stored.push_back(std::move(chunks));
  }
  EXPECT_TRUE(stored[0] == stored[1]) << "the compressed chunks differ between 1 and 2 threads";
}

// A minimal XML check: tags nest and close, attributes are quoted. Returns "" when well-formed, else the problem.
std::string xml_problem(const std::string& text) {
  std::vector<std::string> open;
  std::size_t pos = 0;
  while ((pos = text.find('<', pos)) != std::string::npos) {
    if (text.compare(pos, 4, "<!--") == 0) {
      const auto end = text.find("-->", pos);
      if (end == std::string::npos) return "unterminated comment";
      pos = end + 3;
      continue;
    }
    const auto end = text.find('>', pos);
    if (end == std::string::npos) return "unterminated tag at " + std::to_string(pos);
    const std::string tag = text.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty()) return "empty tag";
    if (tag.front() == '?' || tag.front() == '!') continue;  // declaration, doctype
    if (std::count(tag.begin(), tag.end(), '"') % 2 != 0) return "unbalanced quotes in <" + tag + ">";
    if (tag.front() == '/') {
      const std::string name = tag.substr(1);
      if (open.empty() || open.back() != name)
        return "</" + name + "> closes " + (open.empty() ? "nothing" : "<" + open.back() + ">");
      open.pop_back();
    } else if (tag.back() != '/') {
      open.push_back(tag.substr(0, tag.find_first_of(" \t\n")));
    }
  }
  return open.empty() ? "" : "<" + open.back() + "> is never closed";
}

TEST(Io, XdmfReferencesExistingDatasets) {
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  const std::string xdmf = read_text(run.dir / "result.xdmf");
  ASSERT_FALSE(xdmf.empty());
  EXPECT_EQ(xml_problem(xdmf), "");

  // One uniform grid per frame, times in the order of the frames.
  const std::regex time_re(R"re(<Time Value="([^"]+)"/>)re");
  std::vector<double> times;
  for (auto it = std::sregex_iterator(xdmf.begin(), xdmf.end(), time_re); it != std::sregex_iterator(); ++it)
    times.push_back(std::stod((*it)[1]));
  ASSERT_EQ(times.size(), run.result.frames.size());
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_DOUBLE_EQ(times[k], run.result.frames[k].time);

  // Every HDF DataItem names a dataset of result.h5 (relative to the XDMF file) whose shape is its Dimensions.
  const std::regex item_re(
      R"re(<DataItem Dimensions="([0-9 ]+)"[^>]*Format="HDF">([^<:]+):([^<]+)</DataItem>)re");
  std::size_t items = 0;
  std::map<std::string, int> names;
  for (auto it = std::sregex_iterator(xdmf.begin(), xdmf.end(), item_re); it != std::sregex_iterator(); ++it) {
    ++items;
    const std::string file = (*it)[2], dataset = (*it)[3];
    EXPECT_EQ(file, "result.h5");
    std::vector<std::uint64_t> dims;
    std::istringstream in((*it)[1].str());
    for (std::uint64_t d; in >> d;) dims.push_back(d);
    const auto shape = io::h5_dataset_shape(run.dir / file, dataset);
    ASSERT_TRUE(shape.has_value()) << dataset << " is not in " << file;
    EXPECT_EQ(*shape, dims) << dataset;
    names[dataset.substr(dataset.rfind('/') + 1)]++;
  }
  const int F = int(run.result.frames.size());
  EXPECT_EQ(items, 5u * std::size_t(F));  // connectivity, vertices, layer, damage, rotation per frame
  EXPECT_EQ(names["vertices"], F);
  EXPECT_EQ(names["damage"], F);
  EXPECT_EQ(names["theta"], F);
  for (const char* a : {"Name=\"layer\"", "Name=\"damage\"", "Name=\"rotation\"", "CollectionType=\"Temporal\""})
    EXPECT_NE(xdmf.find(a), std::string::npos) << a;
}

// Every HDF DataItem of `xdmf` names a dataset of a file beside it whose shape is its Dimensions; returns how
// often each dataset name (the last part of its path) is referenced.
std::map<std::string, int> checked_data_items(const std::string& xdmf, const fs::path& dir) {
  const std::regex item_re(
      R"re(<DataItem Dimensions="([0-9 ]+)"[^>]*Format="HDF">([^<:]+):([^<]+)</DataItem>)re");
  std::map<std::string, int> names;
  for (auto it = std::sregex_iterator(xdmf.begin(), xdmf.end(), item_re); it != std::sregex_iterator(); ++it) {
    const std::string file = (*it)[2], dataset = (*it)[3];
    EXPECT_EQ(file, "result.h5");
    std::vector<std::uint64_t> dims;
    std::istringstream in((*it)[1].str());
    for (std::uint64_t d; in >> d;) dims.push_back(d);
    const auto shape = io::h5_dataset_shape(dir / file, dataset);
    EXPECT_TRUE(shape.has_value()) << dataset << " is not in " << file;
    if (shape) {
      EXPECT_EQ(*shape, dims) << dataset;
    }
    names[dataset.substr(dataset.rfind('/') + 1)]++;
  }
  return names;
}

// The force network of every frame of `rbdem ucs` is in result.h5 as the run recorded it: one link per intact bond
// (the bonds less the cracks by then), then the contacts. In the static elastic start the forces across a horizontal
// section through the middle carry the platen force: their vertical components on the blocks above it sum to the
// frame's stress times the loaded area (equilibrium of the upper half; the platen stress of the static solution).
TEST(Io, ForceNetworkIsStoredWithEachFrame) {
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  const TestResult& r = run.result;
  const io::StoredRun s = io::read_result_h5(run.dir / "result.h5");
  ASSERT_EQ(s.frames.size(), r.frames.size());
  const std::size_t bonds = run.specimen.num_bonds();
  int elastic = -1;
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    SCOPED_TRACE(testing::Message() << "frame " << k);
    const ForceNetwork &a = r.frames[k].network, &b = s.frames[k].network;
    EXPECT_EQ(b.i, a.i);
    EXPECT_EQ(b.j, a.j);
    EXPECT_EQ(b.kind, a.kind);
    EXPECT_EQ(b.force, a.force);
    EXPECT_EQ(b.normal_force, a.normal_force);
    EXPECT_EQ(std::size_t(std::count(a.kind.begin(), a.kind.end(), 0)), bonds - r.frames[k].cracks);
    if (r.frames[k].label == "elastic_start") elastic = int(k);
  }
  EXPECT_GT(std::count(r.frames.back().network.kind.begin(), r.frames.back().network.kind.end(), 1), 0)
      << "the final frame of a failed specimen should have contacts";

  ASSERT_GE(elastic, 0);
  const Frame& f = r.frames[std::size_t(elastic)];
  const double* y = f.component(1);
  const double mid = 0.5 * (run.specimen.lo[1] + run.specimen.hi[1]);
  double carried = 0;  // the vertical force on the blocks above the section from those below
  int crossing = 0;
  for (std::size_t k = 0; k < f.network.size(); ++k) {
    const double yi = y[f.network.i[k]], yj = y[f.network.j[k]];
    if ((yi < mid) == (yj < mid)) continue;
    const double fy = f.network.force[2 * k + 1];  // on j
    carried += yj >= mid ? fy : -fy, ++crossing;
  }
  const double area = run.scene.specimen.width * run.scene.specimen.thickness;
  ASSERT_GT(crossing, 10);
  ASSERT_GT(f.stress, 0.0);
  EXPECT_NEAR(carried / area / f.stress, 1.0, 0.01) << carried / area << " Pa against " << f.stress << " Pa";
  std::printf("section at mid-height: %d links carry %.6g Pa, the frame's stress %.6g Pa\n", crossing, carried / area,
              f.stress);

  // forces.xdmf: well formed, one line grid per frame on the network's datasets.
  const std::string xdmf = read_text(run.dir / "forces.xdmf");
  EXPECT_EQ(xml_problem(xdmf), "");
  const std::map<std::string, int> names = checked_data_items(xdmf, run.dir);
  const int F = int(r.frames.size());
  for (const char* n : {"blocks", "centroid", "normal_force", "force", "kind"}) EXPECT_EQ(names.at(n), F) << n;
  EXPECT_EQ(names.size(), 5u);
  for (const char* a : {"TopologyType=\"Polyline\"", "NodesPerElement=\"2\"", "CollectionType=\"Temporal\"",
                        "AttributeType=\"Vector\""})
    EXPECT_NE(xdmf.find(a), std::string::npos) << a;
}

// cracks.csv has one column per field of the crack table, the orientation derived from the normal; fragments.csv
// lists the fragments in the order given.
TEST(Io, SignalFilesHaveOneRowPerEntry) {
  const fs::path dir = fs::temp_directory_path() / ("rbdem_test_io_signals_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const RemoveWhenPassed cleanup{dir};
  Crack c;
  c.bond = 3;
  c.normal = {1.0, 0.0, 0.0};  // a vertical edge
  io::write_cracks_csv(dir / "cracks.csv", 2, {c, c});
  const std::string cracks = read_text(dir / "cracks.csv");
  EXPECT_NE(cracks.find(",orientation_deg\n"), std::string::npos) << cracks;
  EXPECT_EQ(std::count(cracks.begin(), cracks.end(), '\n'), 3) << cracks;
  EXPECT_NE(cracks.find(",90\n"), std::string::npos) << cracks;
  io::write_fragments_csv(dir / "fragments.csv", {Fragment{3, 3.0, 1.5, 0.5}, Fragment{1, 1.0, 4.5, 0.5}});
  EXPECT_EQ(read_text(dir / "fragments.csv"),
            "fragment,blocks,area_m2,area_fraction,x_m,y_m\n0,3,3,0.75,1.5,0.5\n1,1,1,0.25,4.5,0.5\n");
}

// A record is declared once, with its field table (dem/records.hpp), and every writer walks the table: each field
// of the crack table is a column of cracks.csv (in the table's order), a dataset of result.h5's /cracks and, for
// the stored ones, a field of the checkpoint's snapshot holding the run's values. (The Python record is checked
// against cracks.csv in tests/python/test_module.py.) A field added to Crack therefore appears in all of them.
TEST(Records, EveryFieldOfTheCrackTableReachesEveryWriter) {
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  ASSERT_FALSE(run.result.cracks.empty());
  std::vector<std::string> names, stored;
  Crack::fields(2, [&](const Field& f, auto get) {
    names.push_back(f.name);
    if (stored_field<decltype(get), Crack>) stored.push_back(f.name);
  });
  ASSERT_GT(names.size(), stored.size());  // the table has derived fields too (the orientation)
  // cracks.csv: the header is the table.
  const std::string csv = read_text(run.dir / "cracks.csv");
  std::string header;
  for (const auto& n : names) header += (header.empty() ? "" : ",") + n;
  EXPECT_EQ(csv.substr(0, csv.find('\n')), header);
  // result.h5: a dataset per field, one entry per crack.
  for (const auto& n : names)
    EXPECT_EQ(io::h5_dataset_shape(run.dir / "result.h5", "/cracks/" + n),
              (std::vector<std::uint64_t>{run.result.cracks.size()}))
        << n;
  // The checkpoint: a run interrupted after its last crack stores every stored field of the crack log.
  const fs::path file = run.dir / "checkpoint.h5";
  io::CaseOptions co;
  co.run.interrupt_at_step = run.result.steps - 1;
  co.run.checkpoint = [&](const TestCheckpoint& c) { io::write_checkpoint(file, c); };
  EXPECT_THROW(io::run_case("ucs", run.scene, co), RunCancelled);
  const TestCheckpoint ck = io::read_checkpoint(file);
  const auto cracks = read_columns<Crack>(2, [&](const Field& f, auto& column) {
    using V = typename std::decay_t<decltype(column)>::value_type;
    const std::string key = std::string("cracks/") + f.name;
    ASSERT_TRUE(ck.state.has(key)) << key;
    if constexpr (std::is_enum_v<V>) {
      for (auto v : ck.state.get<std::vector<std::uint8_t>>(key)) column.push_back(V(v));
    } else {
      column = ck.state.get<std::vector<V>>(key);
    }
  });
  ASSERT_FALSE(cracks.empty());
  ASSERT_LE(cracks.size(), run.result.cracks.size());
  expect_same_rows(cracks, std::vector<Crack>(run.result.cracks.begin(), run.result.cracks.begin() + long(cracks.size())),
                   2);
  EXPECT_EQ(stored.size(), std::size_t(std::count_if(ck.state.entries.begin(), ck.state.entries.end(), [](const auto& e) {
              return e.name.rfind("cracks/", 0) == 0;
            })));
}

TEST(Io, FailedWriteLeavesNoFileUnderTheFinalName) {
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  TestResult bad = run.result;
  bad.frames.back().pose.pop_back();  // a frame that does not belong to the specimen
  const fs::path h5 = run.dir / "bad.h5";
  EXPECT_THROW(io::write_result_h5(h5, run.scene, run.specimen, bad), std::invalid_argument);
  EXPECT_FALSE(fs::exists(h5));
  EXPECT_FALSE(fs::exists(run.dir / "bad.h5.tmp"));
  EXPECT_THROW(io::read_result_h5(run.dir / "summary.json"), std::runtime_error);  // not an HDF5 file
  EXPECT_THROW(io::read_result_h5(run.dir / "missing.h5"), std::runtime_error);
  EXPECT_FALSE(io::h5_dataset_shape(run.dir / "missing.h5", "/mesh/nodes").has_value());
}

// ------------------------------------------------------------------------------------------------------------------
// The figure script (python/rbdem_figures.py) on the run folder, with Debian's /usr/bin/python3.

const char* python = "/usr/bin/python3";

std::string quote(const fs::path& p) {
  std::string s = "'";  // appended, not `"'" + p.string()`: GCC 12 warns on that (a false -Wrestrict) once inlined
  s += p.string();
  return s += "'";
}

bool python_has_figure_modules() {
  const std::string cmd = std::string(python) + " -c 'import matplotlib, h5py, numpy' > /dev/null 2>&1";
  return fs::exists(python) && std::system(cmd.c_str()) == 0;
}
const char* no_figure_modules =
    " cannot import matplotlib, h5py and numpy (apt-get install python3-matplotlib python3-h5py)";
const fs::path figure_script = fs::path(RBDEM_SOURCE_DIR) / "python" / "rbdem_figures.py";

bool is_png(const fs::path& p) {
  if (!fs::exists(p) || fs::file_size(p) < 1000) return false;
  return read_text(p).compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

TEST(Io, FigureScriptDrawsEveryFigureOfARun) {
  if (!python_has_figure_modules()) GTEST_SKIP() << python << no_figure_modules;
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  ASSERT_TRUE(fs::exists(figure_script)) << figure_script;
  const std::string cmd = std::string(python) + " " + quote(figure_script) + " ";
  const fs::path out = run.dir / "figures";

  // A sweep table as `rbdem sweep` writes it: two groups, Jaeger's curve.
  const fs::path table = run.dir / "table.csv";
  {
    std::ofstream t(table);
    t << "id,group,beta_deg,peak_stress_pa,jaeger_pa\n";
    for (const char* g : {"a", "b"})
      for (int beta = 0; beta <= 90; beta += 15) {
        const double dip = std::sin(beta * std::numbers::pi / 90.0);
        t << g << beta << "," << g << "," << beta << "," << 50e6 - 20e6 * dip << "," << 52e6 - 25e6 * dip << "\n";
      }
  }

  const std::vector<std::pair<std::string, fs::path>> figures = {
      {"stress-strain " + quote(out / "curve.png") + " " + quote(run.dir) + " " + quote(run.dir) +
           " --labels one 'the same'",
       out / "curve.png"},
      {"strength " + quote(out / "strength.png") + " " + quote(table) + " --group group", out / "strength.png"},
      {"cracks " + quote(out / "cracks.png") + " " + quote(run.dir) + " --at both", out / "cracks.png"},
      {"cracks " + quote(out / "cracks_peak.png") + " " + quote(run.dir) + " --at peak --magnify 100",
       out / "cracks_peak.png"},
      {"crack-grid " + quote(out / "grid.png") + " " + quote(run.dir) + " " + quote(run.dir), out / "grid.png"},
      {"stages " + quote(out / "stages.png") + " " + quote(run.dir) + " " + quote(run.dir), out / "stages.png"},
      {"rose " + quote(out / "rose.png") + " " + quote(run.dir) + " --bin 15", out / "rose.png"},
      {"crack-rate " + quote(out / "rate.png") + " " + quote(run.dir), out / "rate.png"},
      {"fragments " + quote(out / "fragments.png") + " " + quote(run.dir) + " --labels one", out / "fragments.png"},
  };
  for (const auto& [args, png] : figures) {
    SCOPED_TRACE(args);
    const std::string c = cmd + args + " > " + quote(run.dir / "figures.log") + " 2>&1";
    EXPECT_EQ(std::system(c.c_str()), 0) << read_text(run.dir / "figures.log");
    EXPECT_TRUE(is_png(png)) << png;
  }

  // The XDMF file parses with a real XML parser too.
  const std::string xml = std::string(python) + " -c 'import sys, xml.etree.ElementTree as E; "
                                                "r = E.parse(sys.argv[1]).getroot(); assert r.tag == \"Xdmf\"' " +
                          quote(run.dir / "result.xdmf");
  EXPECT_EQ(std::system(xml.c_str()), 0);
}

// `batch`: the study reports draw their figures in one Python process, several at a time (study/report.cpp). Each
// figure is reported in list order, drawn or failed with its reason, and a failed one does not stop the others.
TEST(Io, FigureBatchReportsEachFigureInListOrder) {
  if (!python_has_figure_modules()) GTEST_SKIP() << python << no_figure_modules;
  const SmallRun run = small_run();
  const RemoveWhenPassed cleanup{run.dir};
  const fs::path out = run.dir / "batch", missing = run.dir / "no_such_run";
  const std::vector<nlohmann::json> lines = {
      {"stress-strain", (out / "curve.png").string(), run.dir.string()},
      {"rose", (out / "lost.png").string(), missing.string()},
      {"rose", (out / "rose.png").string(), run.dir.string(), "--bin", "15"},
      {"crack-rate", (out / "rate.png").string(), run.dir.string()},
  };
  const fs::path list = run.dir / "figures.jsonl", log = run.dir / "batch.log";
  {
    std::ofstream f(list);
    for (const auto& l : lines) f << l.dump() << "\n";
  }
  const std::string c = std::string(python) + " " + quote(figure_script) + " batch " + quote(list) + " --jobs 2 > " +
                        quote(log) + " 2>&1";
  const int status = std::system(c.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << read_text(log);  // one figure failed
  std::vector<std::string> verdicts;
  {
    std::ifstream f(log);
    for (std::string l; std::getline(f, l);)
      if (l.rfind("drawn ", 0) == 0 || l.rfind("failed ", 0) == 0) verdicts.push_back(l);
  }
  ASSERT_EQ(verdicts.size(), 4u) << read_text(log);
  const std::string drawn = "drawn ", failed = "failed ";
  EXPECT_EQ(verdicts[0], drawn + (out / "curve.png").string());
  EXPECT_EQ(verdicts[1].rfind(failed + (out / "lost.png").string() + ": ", 0), 0u) << verdicts[1];
  EXPECT_NE(verdicts[1].find("no_such_run"), std::string::npos) << verdicts[1];  // the reason names the folder
  EXPECT_EQ(verdicts[2], drawn + (out / "rose.png").string());
  EXPECT_EQ(verdicts[3], drawn + (out / "rate.png").string());
  for (const char* png : {"curve.png", "rose.png", "rate.png"}) EXPECT_TRUE(is_png(out / png)) << png;
  EXPECT_FALSE(fs::exists(out / "lost.png"));
}

}  // namespace
}  // namespace rbdem
