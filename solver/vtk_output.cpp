// VTK XML PolyData frames and the ParaView collection: see vtk_output.hpp.
#include "vtk_output.hpp"

#include <cstdint>
#include <cstring>

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "output.hpp"

namespace chainsim {

namespace {

bool little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

/// Writes the <DataArray> elements of one file: inline text (ascii) or a reference into the appended
/// block (binary), which collects [UInt64 byte count][raw values] per array.
class ArrayWriter {
 public:
  ArrayWriter(std::ostream& out, VtkEncoding encoding) : out_(out), encoding_(encoding) {}

  /// Float64 values, one column per tuple.
  void floats(const std::string& name, const Eigen::MatrixXd& data) {
    open("Float64", name, data.rows());
    if (encoding_ == VtkEncoding::kAscii) {
      out_ << ">\n";
      for (Eigen::Index c = 0; c < data.cols(); ++c) {
        out_ << "          ";
        for (Eigen::Index r = 0; r < data.rows(); ++r) out_ << fmt::format("{} ", data(r, c));
        out_ << '\n';
      }
      out_ << "        </DataArray>\n";
    } else {
      // Eigen stores columns one after another: the tuples in order, as VTK wants them.
      append(data.data(), static_cast<std::size_t>(data.size()) * sizeof(double));
    }
  }

  /// Int32 values (point indices and offsets: a frame has at most 10^7 nodes, see the frame budget).
  void integers(const std::string& name, const std::vector<std::int32_t>& values) {
    open("Int32", name, 1);
    if (encoding_ == VtkEncoding::kAscii) {
      out_ << ">\n          ";
      for (std::int32_t v : values) out_ << v << ' ';
      out_ << "\n        </DataArray>\n";
    } else {
      append(values.data(), values.size() * sizeof(std::int32_t));
    }
  }

  /// The <AppendedData> block (binary only), after the last XML element of the piece.
  void finish() {
    if (encoding_ == VtkEncoding::kAscii) return;
    out_ << "  <AppendedData encoding=\"raw\">\n   _";
    out_.write(appended_.data(), static_cast<std::streamsize>(appended_.size()));
    out_ << "\n  </AppendedData>\n";
  }

 private:
  void open(const char* type, const std::string& name, Eigen::Index components) {
    out_ << fmt::format("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"{}\"", type,
                        name, components, encoding_ == VtkEncoding::kAscii ? "ascii" : "appended");
    if (encoding_ == VtkEncoding::kBinary) out_ << fmt::format(" offset=\"{}\"/>\n", appended_.size());
  }

  void append(const void* data, std::size_t bytes) {
    const std::uint64_t header = bytes;
    appended_.append(reinterpret_cast<const char*>(&header), sizeof header);
    appended_.append(static_cast<const char*>(data), bytes);
  }

  std::ostream& out_;
  VtkEncoding encoding_;
  std::string appended_;
};

}  // namespace

VtkEncoding parse_vtk_encoding(const std::string& text, const std::string& key) {
  if (text == "binary") return VtkEncoding::kBinary;
  if (text == "ascii") return VtkEncoding::kAscii;
  throw InputError(fmt::format("{} = \"{}\" is not allowed; valid values: binary, ascii", key, text));
}

void write_vtp(const std::filesystem::path& path, const VtkPolyline& line, VtkEncoding encoding) {
  const auto np = line.points.cols();
  const auto nc = static_cast<Eigen::Index>(line.segments.size());
  const Eigen::Index nv = line.vertices ? np : static_cast<Eigen::Index>(line.vertex_cells.size());
  for (const auto& [name, data] : line.point_data)
    CHAINSIM_VERIFY(data.cols() == np, "VTK point data '" + name + "' needs one column per point");
  for (const auto& [name, data] : line.cell_data)
    CHAINSIM_VERIFY(data.cols() == (line.vertices ? nc : nv + nc),
                    "VTK cell data '" + name + "' needs one column per cell");
  CHAINSIM_VERIFY(2 * static_cast<double>(nc) < 2147483647.0, "too many VTK line cells for Int32 offsets");
  CHAINSIM_VERIFY(!line.vertices || (line.segments.empty() && line.cell_data.empty() && line.vertex_cells.empty()),
                  "a vertex set has no line cells and no cell data");
  std::vector<std::int32_t> connectivity, offsets, vertex_connectivity, vertex_offsets;
  for (const auto& [a, b] : line.segments) {
    connectivity.push_back(a);
    connectivity.push_back(b);
    offsets.push_back(static_cast<std::int32_t>(connectivity.size()));
  }
  for (Eigen::Index q = 0; q < nv; ++q) {
    vertex_connectivity.push_back(line.vertices ? static_cast<std::int32_t>(q) : line.vertex_cells[static_cast<std::size_t>(q)]);
    vertex_offsets.push_back(static_cast<std::int32_t>(vertex_connectivity.size()));
  }
  AtomicFile file(path);
  auto& out = file.stream();
  out << fmt::format("<?xml version=\"1.0\"?>\n"
                     "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"{}\" header_type=\"UInt64\">\n"
                     "  <PolyData>\n",
                     little_endian() ? "LittleEndian" : "BigEndian");
  out << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" "
                     "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
                     np, nv, nc);
  ArrayWriter arrays(out, encoding);
  out << "      <Points>\n";
  arrays.floats("Points", line.points);
  out << "      </Points>\n";
  // The cells: a vertex set's Verts, a line's Lines, or (vertex cells listed besides the segments) both.
  auto cells = [&](const char* kind, const std::vector<std::int32_t>& conn, const std::vector<std::int32_t>& offs) {
    out << fmt::format("      <{}>\n", kind);
    arrays.integers("connectivity", conn);
    arrays.integers("offsets", offs);
    out << fmt::format("      </{}>\n", kind);
  };
  if (nv > 0 || line.vertices) cells("Verts", vertex_connectivity, vertex_offsets);
  if (!line.vertices) cells("Lines", connectivity, offsets);
  out << "      <PointData>\n";
  for (const auto& [name, data] : line.point_data) arrays.floats(name, data);
  out << "      </PointData>\n      <CellData>\n";
  for (const auto& [name, data] : line.cell_data) arrays.floats(name, data);
  out << "      </CellData>\n    </Piece>\n  </PolyData>\n";
  arrays.finish();
  out << "</VTKFile>\n";
  file.commit();
}

void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& frames) {
  AtomicFile file(path);
  auto& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (const PvdEntry& f : frames)
    out << fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", f.t, f.part, f.file);
  out << "  </Collection>\n</VTKFile>\n";
  file.commit();
}

}  // namespace chainsim
