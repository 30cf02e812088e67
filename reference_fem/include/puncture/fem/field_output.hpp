// field_output.hpp: ParaView time series of the FEM fields.
//
// In:  a FiniteStrainSolver (its displacement and per-cell fields), the time
//      of the frame (s), an output folder and a base name.
// Out: per frame <base>_<frame>.<rank>.vtu (one piece per MPI rank) and
//      <base>_<frame>.pvtu (rank 0); write_collection() writes <base>.pvd
//      (rank 0) listing every frame with its time. Fields: displacement (m,
//      point vector), layer_id, removed (1 for void cells), J (cell mean),
//      von_mises_Pa (cell mean of the Cauchy von Mises stress),
//      max_principal_stretch (cell max). Every file is written under a
//      temporary name and renamed when complete (io::write_file_atomically,
//      core/io/atomic_file.hpp: the staged file is removed on SIGINT/SIGTERM).
#pragma once

#include <mpi.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace puncture::fem {

class FiniteStrainSolver;

class FieldOutputSeries {
 public:
  FieldOutputSeries(std::filesystem::path folder, std::string base_name, MPI_Comm comm);

  /// Writes one frame; returns the file names written by this rank.
  std::vector<std::string> write_frame(const FiniteStrainSolver& solver, double time_s);

  /// Writes <base>.pvd (rank 0 only; other ranks return an empty string).
  std::string write_collection() const;

  std::size_t n_frames() const { return frames_.size(); }

 private:
  std::filesystem::path folder_;
  std::string base_name_;
  MPI_Comm comm_;
  std::vector<std::pair<double, std::string>> frames_;  ///< (time s, pvtu name)
};

}  // namespace puncture::fem
