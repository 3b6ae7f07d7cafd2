// Standalone probe of MuJoCo 2.2.2 (Debian libmujoco-dev) for the README's evaluation of it
// as a 2-D engine: what a bounce's coefficient of restitution is under MuJoCo's soft
// contacts. A sphere on two slide joints (x, z: the plane) falls onto a plane; the probe
// prints v_out / v_in for impact speeds and contact parameters (solref). Not part of
// physval (build target physval_probe_mujoco, run with no arguments).
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

// v_out / v_in of the first bounce of a sphere (r = 0.5, m = 1) arriving at v_in, no gravity
// (the sphere starts 0.1 m above the plane), timestep dt, the plane's and sphere's solref.
double bounce(double v_in, const char* solref, double dt, double* max_depth) {
  char xml[2048];
  std::snprintf(xml, sizeof xml,
                "<mujoco><option timestep=\"%.17g\" gravity=\"0 0 0\" integrator=\"Euler\"/>"
                "<worldbody><geom type=\"plane\" size=\"10 10 0.1\" solref=\"%s\"/>"
                "<body pos=\"0 0 0.6\"><joint type=\"slide\" axis=\"1 0 0\"/><joint type=\"slide\" axis=\"0 0 1\"/>"
                "<geom type=\"sphere\" size=\"0.5\" mass=\"1\" solref=\"%s\"/></body></worldbody></mujoco>",
                dt, solref, solref);
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  const int len = static_cast<int>(std::strlen(xml));
  mj_makeEmptyFileVFS(&vfs, "ball.xml", len);
  std::memcpy(vfs.filedata[mj_findFileVFS(&vfs, "ball.xml")], xml, static_cast<std::size_t>(len));
  char error[512] = "";
  mjModel* m = mj_loadXML("ball.xml", &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  if (m == nullptr) {
    std::printf("load error: %s\n", error);
    return NAN;
  }
  mjData* d = mj_makeData(m);
  d->qvel[1] = -v_in;   // the z slide
  double depth = 0.0;
  bool touched = false;
  double v_out = NAN;
  for (int i = 0; i < 200000; ++i) {
    mj_step(m, d);
    const double gap = d->qpos[1] + 0.6 - 0.5;   // the ball's bottom above the plane
    depth = std::fmax(depth, -gap);
    if (gap < 0.0) touched = true;
    if (touched && gap > 0.01) {
      v_out = d->qvel[1];
      break;
    }
  }
  *max_depth = depth;
  mj_deleteData(d);
  mj_deleteModel(m);
  return v_out / v_in;
}

}  // namespace

int main() {
  const int v = mj_version();
  std::printf("MuJoCo %d.%d.%d (mj_version %d), Euler integrator, no gravity, sphere r = 0.5 m, m = 1 kg onto a plane\n",
              v / 100, (v / 10) % 10, v % 10, v);
  for (const char* solref : {"0.02 1", "0.02 0.1", "-10000 0", "-1000000 0"}) {
    for (double dt : {1.0 / 60.0, 1.0 / 1000.0}) {
      for (double v : {0.1, 1.0, 10.0}) {
        double depth = 0.0;
        const double e = bounce(v, solref, dt, &depth);
        std::printf("solref \"%s\" dt %.4g: v_in %-4g -> v_out / v_in = %.4f (deepest overlap %.3g m)\n", solref, dt, v, e,
                    depth);
      }
    }
  }
  return 0;
}
