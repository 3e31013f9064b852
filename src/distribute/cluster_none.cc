// distribute/cluster.h in a build without MPI: a process is always alone.
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "distribute/cluster.h"

namespace diverse {

struct Cluster::Impl {};

bool cluster_support() { return false; }

Cluster::Cluster(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Cluster::~Cluster() = default;

std::unique_ptr<Cluster> Cluster::join() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  if (size && std::atoi(size) > 1)
    throw UserError(
        "mpirun: this build of diverse has no MPI support; install Open MPI (Debian: "
        "libopenmpi-dev openmpi-bin, see scripts/setup.sh) and configure the build again");
  return nullptr;
}

namespace {
[[noreturn]] void no_mpi() { throw std::logic_error("Cluster: this build has no MPI"); }
}  // namespace

int Cluster::rank() const { return 0; }
int Cluster::size() const { return 1; }
void Cluster::set_rank_timeout(double) {}
int Cluster::default_threads() const { return ThreadPool::hardware_threads(); }
void Cluster::start_workers(const std::string&) { no_mpi(); }
std::unique_ptr<BatchEvaluator> Cluster::evaluator(const DiversityProblem&, ThreadPool&, Decode) { no_mpi(); }
void Cluster::set_stop_message(const std::string&) {}
Cluster::Traffic Cluster::traffic() const { return {}; }
bool Cluster::receive_setup(std::string*) { no_mpi(); }
void Cluster::refuse_setup(const std::string&) { no_mpi(); }
void Cluster::serve(const DiversityProblem&, int, Encode) { no_mpi(); }

}  // namespace diverse
