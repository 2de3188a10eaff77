// VTK XML PolyData frames and the ParaView collection: see vtk_output.hpp.
#include "vtk_output.hpp"

#include <fmt/format.h>

#include "mesh/errors.hpp"
#include "output.hpp"

namespace chainsim {

namespace {
void write_array(std::ostream& out, const std::string& name, const Eigen::MatrixXd& data) {
  out << fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                     name, data.rows());
  for (Eigen::Index c = 0; c < data.cols(); ++c) {
    out << "          ";
    for (Eigen::Index r = 0; r < data.rows(); ++r) out << fmt::format("{:.10g} ", data(r, c));
    out << '\n';
  }
  out << "        </DataArray>\n";
}
}  // namespace

void write_vtp(const std::filesystem::path& path, const VtkPolyline& line) {
  const auto np = line.points.cols();
  const auto nc = static_cast<Eigen::Index>(line.segments.size());
  for (const auto& [name, data] : line.point_data)
    CHAINSIM_VERIFY(data.cols() == np, "VTK point data '" + name + "' needs one column per point");
  for (const auto& [name, data] : line.cell_data)
    CHAINSIM_VERIFY(data.cols() == nc, "VTK cell data '" + name + "' needs one column per segment");
  AtomicFile file(path);
  auto& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <PolyData>\n";
  out << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" "
                     "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
                     np, nc);
  out << "      <Points>\n";
  write_array(out, "Points", line.points);
  out << "      </Points>\n      <Lines>\n"
         "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n          ";
  for (const auto& [a, b] : line.segments) out << a << ' ' << b << ' ';
  out << "\n        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n          ";
  for (Eigen::Index k = 1; k <= nc; ++k) out << 2 * k << ' ';
  out << "\n        </DataArray>\n      </Lines>\n";
  out << "      <PointData>\n";
  for (const auto& [name, data] : line.point_data) write_array(out, name, data);
  out << "      </PointData>\n      <CellData>\n";
  for (const auto& [name, data] : line.cell_data) write_array(out, name, data);
  out << "      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  file.commit();
}

void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames) {
  AtomicFile file(path);
  auto& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (const auto& [t, name] : frames)
    out << fmt::format("    <DataSet timestep=\"{:.12g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", t, name);
  out << "  </Collection>\n</VTKFile>\n";
  file.commit();
}

}  // namespace chainsim
