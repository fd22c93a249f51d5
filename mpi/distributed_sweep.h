#pragma once
/// \file Dealing independent pieces of work (the units of `raysift sweep`, sampling/sweep.h) to the MPI ranks and
/// collecting their text on rank 0 in unit order. Key decision: a static round-robin deal, unit u on rank
/// u % size: the units are interleaved kinds (fractions, budgets, knobs) of every study point, so neighbouring
/// units of unequal cost land on different ranks, and no master rank sits idle handing out work.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace raysift::mpi {

/// The units `rank` of `size` runs, ascending: u with u % size == rank. \pre 0 <= rank < size
std::vector<std::size_t> dealt_units(std::size_t units, int rank, int size);

/// Runs one rank's units (dealt_units order) and returns one text per unit.
using UnitRunner = std::function<std::vector<std::string>(const std::vector<std::size_t>& units)>;

/// \brief Collective: every rank runs its dealt units; rank 0 returns every unit's text in unit order, the other
/// ranks an empty vector. A failure on any rank throws RankFailure on every rank (mpi::all_or_none).
/// \throw InvalidInput (on every rank) when `run` returns a text count other than its unit count.
std::vector<std::string> deal_and_gather(std::size_t units, const UnitRunner& run);

}  // namespace raysift::mpi
