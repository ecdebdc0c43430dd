#include <strata/sim/mpi/ranks.hpp>

#include <algorithm>
#include <climits>

#include <strata/core/check.hpp>
#include <strata/core/interrupt.hpp>

namespace strata::sim {

void allreduceExact(ExactSum* sums, int n, MPI_Comm comm) {
  MPI_Datatype type;
  MPI_Type_contiguous(int(sizeof(ExactSum)), MPI_BYTE, &type);
  MPI_Type_commit(&type);
  MPI_Op op;
  MPI_Op_create(
      [](void* in, void* inout, int* len, MPI_Datatype*) {
        const auto* a = static_cast<const ExactSum*>(in);
        auto* b = static_cast<ExactSum*>(inout);
        for (int i = 0; i < *len; ++i) b[i] += a[i];
      },
      1, &op);
  MPI_Allreduce(MPI_IN_PLACE, sums, n, type, op, comm);
  MPI_Op_free(&op);
  MPI_Type_free(&type);
}

Ranks Ranks::of(MPI_Comm comm) {
  Ranks r;
  r.distributed_ = true;
  r.comm_ = comm;
  MPI_Comm_rank(comm, &r.rank_);
  MPI_Comm_size(comm, &r.size_);
  return r;
}

int Ranks::onThisMachine() const {
  if (!distributed_) return 1;
  MPI_Comm machine = MPI_COMM_NULL;
  MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &machine);
  int n = 1;
  MPI_Comm_size(machine, &n);
  MPI_Comm_free(&machine);
  return n;
}

Status Ranks::agree(const Status& local) const {
  if (!distributed_) return local;
  int failing = local.ok() ? INT_MAX : rank_, first = INT_MAX;
  MPI_Allreduce(&failing, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == INT_MAX) return {};
  std::string msg = local.ok() ? std::string() : local.message();
  int len = int(msg.size());
  MPI_Bcast(&len, 1, MPI_INT, first, comm_);
  msg.resize(size_t(len));
  MPI_Bcast(msg.data(), len, MPI_CHAR, first, comm_);
  return fail(first == 0 ? msg : "rank " + std::to_string(first) + ": " + msg);
}

bool Ranks::anyInterrupted() const {
  if (!distributed_) return interrupted();
  int mine = interrupted() ? 1 : 0, any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm_);
  return any != 0;
}

std::string Ranks::fromLead(std::string bytes) const {
  if (!distributed_) return bytes;
  unsigned long long n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm_);
  bytes.resize(size_t(n));
  // In pieces of at most INT_MAX bytes (MPI counts are int).
  for (size_t at = 0; at < bytes.size(); at += size_t(INT_MAX)) {
    MPI_Bcast(bytes.data() + at, int(std::min<size_t>(INT_MAX, bytes.size() - at)), MPI_CHAR, 0, comm_);
  }
  return bytes;
}

std::pair<long long, long long> Ranks::minMax(long long value) const {
  if (!distributed_) return {value, value};
  long long lo = 0, hi = 0;
  MPI_Allreduce(&value, &lo, 1, MPI_LONG_LONG, MPI_MIN, comm_);
  MPI_Allreduce(&value, &hi, 1, MPI_LONG_LONG, MPI_MAX, comm_);
  return {lo, hi};
}

bool Ranks::all(bool value) const { return minMax(value ? 1 : 0).first == 1; }

void Ranks::sum(std::vector<ExactSum>& sums) const {
  if (distributed_) allreduceExact(sums.data(), int(sums.size()), comm_);
}

void Ranks::min(std::vector<double>& values) const {
  if (distributed_) MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MIN, comm_);
}

void Ranks::max(std::vector<double>& values) const {
  if (distributed_) MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MAX, comm_);
}

namespace {

// Each rank's offset in a gather of `counts` bytes (under 2 GB in all: MPI counts are int).
std::vector<int> offsetsOf(const std::vector<int>& counts) {
  std::vector<int> offsets(counts.size());
  size_t total = 0;
  for (size_t r = 0; r < counts.size(); ++r) {
    offsets[r] = int(total);
    total += size_t(counts[r]);
  }
  STRATA_CHECK(total < size_t(INT_MAX)) << "a gather over the ranks exceeds 2 GB";
  return offsets;
}

// The gathered bytes back as each rank's part.
std::vector<std::string> partsOf(const std::string& all, const std::vector<int>& counts,
                                 const std::vector<int>& offsets) {
  std::vector<std::string> out;
  for (size_t r = 0; r < counts.size(); ++r) out.push_back(all.substr(size_t(offsets[r]), size_t(counts[r])));
  return out;
}

}  // namespace

std::vector<std::string> Ranks::gatherToLead(const std::string& bytes) const {
  if (!distributed_) return {bytes};
  STRATA_CHECK(bytes.size() < size_t(INT_MAX)) << "a rank's part of a gather exceeds 2 GB";
  int n = int(bytes.size());
  std::vector<int> counts(static_cast<size_t>(size_)), offsets;
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  std::string all;
  if (lead()) {
    offsets = offsetsOf(counts);
    all.resize(size_t(offsets.back()) + size_t(counts.back()));
  }
  MPI_Gatherv(bytes.data(), n, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR, 0, comm_);
  return lead() ? partsOf(all, counts, offsets) : std::vector<std::string>{};
}

std::vector<std::string> Ranks::allGatherBytes(const std::string& bytes) const {
  if (!distributed_) return {bytes};
  STRATA_CHECK(bytes.size() < size_t(INT_MAX)) << "a rank's part of a gather exceeds 2 GB";
  int n = int(bytes.size());
  std::vector<int> counts(static_cast<size_t>(size_));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  const std::vector<int> offsets = offsetsOf(counts);
  std::string all(size_t(offsets.back()) + size_t(counts.back()), '\0');
  MPI_Allgatherv(bytes.data(), n, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR, comm_);
  return partsOf(all, counts, offsets);
}

std::pair<std::string, std::string> Ranks::swapWithNeighbours(const std::string& up, const std::string& down) const {
  if (!distributed_) return {};
  const int before = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL, after = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  STRATA_CHECK(up.size() < size_t(INT_MAX) && down.size() < size_t(INT_MAX)) << "a rank's part of a swap exceeds 2 GB";
  int upCount = int(up.size()), downCount = int(down.size()), fromBefore = 0, fromAfter = 0;
  MPI_Sendrecv(&upCount, 1, MPI_INT, before, 0, &fromAfter, 1, MPI_INT, after, 0, comm_, MPI_STATUS_IGNORE);
  MPI_Sendrecv(&downCount, 1, MPI_INT, after, 1, &fromBefore, 1, MPI_INT, before, 1, comm_, MPI_STATUS_IGNORE);
  std::pair<std::string, std::string> got{std::string(size_t(fromBefore), '\0'), std::string(size_t(fromAfter), '\0')};
  MPI_Sendrecv(up.data(), upCount, MPI_CHAR, before, 2, got.second.data(), fromAfter, MPI_CHAR, after, 2, comm_,
               MPI_STATUS_IGNORE);
  MPI_Sendrecv(down.data(), downCount, MPI_CHAR, after, 3, got.first.data(), fromBefore, MPI_CHAR, before, 3, comm_,
               MPI_STATUS_IGNORE);
  return got;
}

std::vector<double> Ranks::allGather(const std::vector<double>& values) const {
  if (!distributed_) return values;
  std::vector<double> all(values.size() * size_t(size_));
  MPI_Allgather(values.data(), int(values.size()), MPI_DOUBLE, all.data(), int(values.size()), MPI_DOUBLE, comm_);
  return all;
}

}  // namespace strata::sim
