#pragma once
/// @file vtk_output.hpp
/// ParaView-readable output: one VTK XML PolyData file (.vtp) per frame and a .pvd collection that
/// lists them with their times, so ParaView plays the run as a time series.
///
/// A string frame is a set of line cells, one per link (so per-link data such as the tension is
/// cell data); node data (velocity, …) is point data. A set of marked points (the fronts of a frame)
/// is a PolyData of vertex cells, one per point. A collection (.pvd) may hold several parts per time
/// (the string as part 0, its fronts as part 1). Points are always 3D for VTK: a 2D string is
/// written with z = 0. Files are written through AtomicFile, in one of two encodings:
///   - binary (default): every array as raw little- or big-endian (the machine's, declared in the file)
///     bytes in one AppendedData block (encoding "raw"), each preceded by its size in bytes (UInt64
///     header); exact, and about a third of the ASCII size;
///   - ascii: the values as text, each double in the shortest form that reads back to the same double
///     (so also exact); readable by eye, larger and slower to read.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace chainsim {

struct VtkPolyline {
  Eigen::Matrix3Xd points;                    ///< one column per node (m)
  std::vector<std::pair<int, int>> segments;  ///< node pairs, one per link
  bool vertices = false;                      ///< no lines: one vertex cell per point (cell data: none)
  /// Points drawn as vertex cells besides the segments (an obstacle's drawing): cell data then has one
  /// column per vertex cell first, then one per segment (VTK's order of a piece's cells).
  std::vector<int> vertex_cells;
  /// Named point data: rows = components (1 or 3), one column per point.
  std::vector<std::pair<std::string, Eigen::MatrixXd>> point_data;
  /// Named cell data: rows = components, one column per segment (per vertex cell, then per segment).
  std::vector<std::pair<std::string, Eigen::MatrixXd>> cell_data;
};

enum class VtkEncoding { kBinary, kAscii };

/// "binary" | "ascii" -> the encoding; throws InputError naming `key` and the allowed values otherwise.
VtkEncoding parse_vtk_encoding(const std::string& text, const std::string& key = "vtk_encoding");

/// Writes one frame as a VTK XML PolyData file.
void write_vtp(const std::filesystem::path& path, const VtkPolyline& line,
               VtkEncoding encoding = VtkEncoding::kBinary);

/// One file of a ParaView collection.
struct PvdEntry {
  double t = 0;      ///< time (s)
  std::string file;  ///< relative to the .pvd
  int part = 0;      ///< which part of the scene at that time (0: the string, 1: its fronts, 2: the obstacles)
};
/// Writes the ParaView collection.
void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& frames);

}  // namespace chainsim
