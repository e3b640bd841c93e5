#include "outputs.h"

#include <bit>
#include <stdexcept>

namespace fluidcast::tools {
namespace {
std::ofstream open_for_writing(const std::filesystem::path& path, std::ios::openmode mode) {
  std::ofstream out(path, mode);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  return out;
}
}  // namespace

StatsCsv::StatsCsv(const std::filesystem::path& path)
    : out_(open_for_writing(path, std::ios::out)) {
  out_ << "step,t,particles,kinetic_energy,max_density_error,avg_density_error,front_x,"
          "com_x,com_y,com_z,max_speed,spray,substeps\n";
  out_.precision(9);
}

void StatsCsv::write(std::uint64_t step, double time, const sim::FluidStatistics& s,
                     int substeps) {
  out_ << step << ',' << time << ',' << s.particles << ',' << s.kinetic_energy << ','
       << s.max_density_error << ',' << s.avg_density_error << ',' << s.front_x << ','
       << s.centre_of_mass.x << ',' << s.centre_of_mass.y << ',' << s.centre_of_mass.z << ','
       << s.max_speed << ',' << s.spray_share << ',' << substeps << '\n';
}

void write_ply(const std::filesystem::path& path, const sim::ParticleSet& particles) {
  static_assert(std::endian::native == std::endian::little, "PLY dumps are written little-endian");
  std::ofstream out = open_for_writing(path, std::ios::out | std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\ncomment fluidcast particles, SI units\n"
      << "element vertex " << particles.size() << '\n'
      << "property float x\nproperty float y\nproperty float z\n"
      << "property float vx\nproperty float vy\nproperty float vz\nend_header\n";
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const float record[6] = {particles.position[i].x, particles.position[i].y,
                             particles.position[i].z, particles.velocity[i].x,
                             particles.velocity[i].y, particles.velocity[i].z};
    out.write(reinterpret_cast<const char*>(record), sizeof(record));
  }
  if (!out) throw std::runtime_error("failed writing " + path.string());
}

}  // namespace fluidcast::tools
