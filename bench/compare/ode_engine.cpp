// The mobile in ODE (maximal coordinates): one body per moving component, its frame = the component's
// principal frame at its centre of mass (so the mass is set with the centre at the body origin and the
// principal moments on the diagonal), one ball joint per component attached to its parent's body or,
// for a component hanging from the hook, to the static environment (body 0), anchored at the joint's
// world point at rest. Gravity from the model; ODE's defaults otherwise: ERP 0.2, CFM 1e-10 (double),
// 20 quick-step iterations, no damping, gyroscopic term on, auto-disable off.

#include <ode/ode.h>

#include <mutex>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "compare/engine.hpp"

namespace aloft::compare {
namespace {

void init_ode_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    if (!dCheckConfiguration("ODE_double_precision"))
      throw std::runtime_error("aloft_compare needs ODE built in double precision");
  });
}

class OdeEngine : public Engine {
 public:
  OdeEngine(const Model& model, const State& initial, double timestep, bool quick)
      : model_(model), timestep_(timestep), quick_(quick) {
    init_ode_once();
    world_ = dWorldCreate();
    dWorldSetGravity(world_, model.gravity.x(), model.gravity.y(), model.gravity.z());
    bodies_.assign(model.count, nullptr);
    // Bodies at the designed pose first (ball anchors are taken relative to the bodies' poses).
    for (int i = 1; i < model.count; ++i) {
      dBodyID b = dBodyCreate(world_);
      dMass mass;
      const Vec3& moments = model.principal_moments[i];
      dMassSetParameters(&mass, model.mass[i], 0, 0, 0, moments.x(), moments.y(), moments.z(), 0, 0, 0);
      dBodySetMass(b, &mass);
      const Vec3& x = model.rest_position[i];
      dBodySetPosition(b, x.x(), x.y(), x.z());
      const Quat& q = model.rest_orientation[i];
      const dQuaternion dq = {q.w(), q.x(), q.y(), q.z()};
      dBodySetQuaternion(b, dq);
      bodies_[i] = b;
    }
    for (int i = 1; i < model.count; ++i) {
      dJointID joint = dJointCreateBall(world_, nullptr);
      const int p = model.parent[i];
      dJointAttach(joint, bodies_[i], p == 0 ? nullptr : bodies_[p]);
      const Vec3& j = model.joint_world[i];
      dJointSetBallAnchor(joint, j.x(), j.y(), j.z());
    }
    // Then the initial state (at the designed pose, so the anchors stay consistent).
    for (int i = 1; i < model.count; ++i) {
      if ((initial.position[i] - model.rest_position[i]).norm() > 1e-12 ||
          initial.orientation[i].angularDistance(model.rest_orientation[i]) > 1e-12)
        throw std::invalid_argument("ODE engine: the initial state must be the designed pose");
      const Vec3& v = initial.velocity[i];
      const Vec3& w = initial.angular[i];
      dBodySetLinearVel(bodies_[i], v.x(), v.y(), v.z());
      dBodySetAngularVel(bodies_[i], w.x(), w.y(), w.z());
    }
  }

  ~OdeEngine() override { dWorldDestroy(world_); }  // destroys its bodies and joints

  std::string name() const override { return quick_ ? "ODE quick" : "ODE step"; }

  void step() override {
    const int ok = quick_ ? dWorldQuickStep(world_, timestep_) : dWorldStep(world_, timestep_);
    if (!ok) throw std::runtime_error(name() + ": step failed (out of memory)");
  }

  void read(State& out) override {
    for (int i = 1; i < model_.count; ++i) {
      const dReal* x = dBodyGetPosition(bodies_[i]);
      const dReal* q = dBodyGetQuaternion(bodies_[i]);  // w, x, y, z
      const dReal* v = dBodyGetLinearVel(bodies_[i]);
      const dReal* w = dBodyGetAngularVel(bodies_[i]);
      out.position[i] = Vec3(x[0], x[1], x[2]);
      out.orientation[i] = Quat(q[0], q[1], q[2], q[3]).normalized();
      out.velocity[i] = Vec3(v[0], v[1], v[2]);
      out.angular[i] = Vec3(w[0], w[1], w[2]);
    }
  }

 private:
  const Model& model_;
  double timestep_;
  bool quick_;
  dWorldID world_ = nullptr;
  std::vector<dBodyID> bodies_;
};

}  // namespace

std::unique_ptr<Engine> make_ode(const Model& model, const State& initial, double timestep, bool quick) {
  return std::make_unique<OdeEngine>(model, initial, timestep, quick);
}

std::string ode_configuration() {
  init_ode_once();
  dWorldID world = dWorldCreate();
  std::ostringstream out;
  out << "ODE (" << dGetConfiguration() << "), world defaults: ERP " << dWorldGetERP(world) << ", CFM "
      << dWorldGetCFM(world) << ", " << dWorldGetQuickStepNumIterations(world) << " quick-step iterations, SOR w "
      << dWorldGetQuickStepW(world) << ".";
  dWorldDestroy(world);
  return out.str();
}

}  // namespace aloft::compare
