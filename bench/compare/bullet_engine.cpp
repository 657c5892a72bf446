// The mobile as a Bullet btMultiBody (Featherstone's articulated-body algorithm, reduced coordinates).
//
// Base: the fixed component (the hook), fixed, its frame = the hook's principal frame at rest. Link k
// (0-based) is Aloft component k + 1, with Bullet parent index parent[k + 1] - 1 (-1 = the base); Aloft
// orders components depth first with parent[i] < i, which is the order Bullet needs. A link's frame is
// its centre of mass with the principal axes, so its inertia is the diagonal of principal moments, and
//   rotParentToThis            = q_i^-1 q_p at rest (q = body -> world), so joint rotation 0 = rest pose
//   parentComToThisPivotOffset = joint_in_parent[i]  (parent's centre of mass -> joint, parent frame)
//   thisPivotToThisComOffset   = -joint_in_child[i]  (joint -> own centre of mass, own frame).
// A spherical joint's 3 velocities are the angular velocity of the link relative to its parent, in the
// link's frame. No damping, gyroscopic term on, no sleeping.
//
// Collisions (on request): each component, the hook too, gets a btMultiBodyLinkCollider whose shape is a
// compound of Aloft's own convex pieces (collision/convex_pieces.hpp, in the same body frame): a sphere
// as btSphereShape, a wire as btCylinderShape (Y along its axis), a plate's part as btConvexHullShape of
// its vertices, grown by kHullMargin (Bullet's hulls are rounded by their margin; a cylinder keeps its
// size, its margin taken inside). Links collide with each other except with their parents (Aloft's
// joints are no contacts either), with the mobile's restitution and friction (Bullet gives a pair the
// product of its two objects' coefficients, so each collider has their square roots), through Bullet's usual
// pipeline (btDbvtBroadphase, compound-compound GJK/EPA, btMultiBodyConstraintSolver's projected
// Gauss-Seidel, 10 iterations) at its defaults otherwise.

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "collision/convex_pieces.hpp"
#include "compare/engine.hpp"

#ifndef BT_USE_DOUBLE_PRECISION
#error "aloft_compare must use Bullet's double-precision build (pkg-config bullet-float64)"
#endif

namespace aloft::compare {
namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
btQuaternion to_bt(const Quat& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
Vec3 from_bt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
Quat from_bt(const btQuaternion& q) { return Quat(q.w(), q.x(), q.y(), q.z()); }

// m: how much Bullet grows a plate's hull (its default, 4 cm, is twenty times a plate's thickness), and
// the most a wire's margin may be (at most half its radius).
constexpr double kHullMargin = 1e-4;

class BulletEngine : public Engine {
 public:
  BulletEngine(const Model& model, const State& initial, double timestep, bool collisions)
      : model_(model),
        timestep_(timestep),
        dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_) {
    const int links = model.count - 1;
    body_ = std::make_unique<btMultiBody>(links, 1.0, btVector3(1, 1, 1), /*fixedBase=*/true,
                                          /*canSleep=*/false);
    body_->setBaseWorldTransform(btTransform(to_bt(model.rest_orientation[0]), to_bt(model.rest_position[0])));
    for (int i = 1; i < model.count; ++i) {
      const int p = model.parent[i];
      const Quat parent_to_this = model.rest_orientation[i].conjugate() * model.rest_orientation[p];
      body_->setupSpherical(i - 1, model.mass[i], to_bt(model.principal_moments[i]), p - 1, to_bt(parent_to_this),
                            to_bt(model.joint_in_parent[i]), to_bt(-model.joint_in_child[i]),
                            /*disableParentCollision=*/true);
    }
    body_->finalizeMultiDof();
    body_->setLinearDamping(0);
    body_->setAngularDamping(0);
    body_->setUseGyroTerm(true);
    body_->setHasSelfCollision(collisions);
    body_->setCanSleep(false);
    body_->setMaxCoordinateVelocity(1e30);  // default 100 rad/s clamps joint velocities
    world_.setGravity(to_bt(model.gravity));
    world_.addMultiBody(body_.get());
    if (collisions) add_colliders();

    // Initial state: the designed pose (joint rotations 0) with the relative angular velocities.
    for (int i = 1; i < model.count; ++i) {
      if ((initial.position[i] - model.rest_position[i]).norm() > 1e-12 ||
          initial.orientation[i].angularDistance(model.rest_orientation[i]) > 1e-12)
        throw std::invalid_argument("Bullet engine: the initial state must be the designed pose");
      const Vec3 relative = model.rest_orientation[i].conjugate() * (initial.angular[i] - initial.angular[model.parent[i]]);
      const double qdot[3] = {relative.x(), relative.y(), relative.z()};
      body_->setJointVelMultiDof(i - 1, qdot);
    }
    rotation_.resize(model.count);
  }

  ~BulletEngine() override {
    for (auto& collider : colliders_) world_.removeCollisionObject(collider.get());
    world_.removeMultiBody(body_.get());
  }

  std::string name() const override { return "Bullet"; }

  void step() override {
    world_.stepSimulation(timestep_, 0, timestep_);
    if (colliders_.empty()) return;
    points_ = 0;
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_.getManifoldByIndexInternal(m);
      points_ += manifold->getNumContacts();
      for (int k = 0; k < manifold->getNumContacts(); ++k)
        deepest_ = std::max(deepest_, -static_cast<double>(manifold->getContactPoint(k).getDistance()));
    }
  }

  int contact_points() const override { return points_; }
  double deepest_overlap() const override { return deepest_; }

  // World poses and velocities from the joint coordinates, base to tips: with R_i the link's rotation
  // (link -> world), w_i = w_p + R_i qdot_i and v_i = v_p + w_p x (j_i - x_p) + w_i x (x_i - j_i).
  void read(State& out) override {
    const btQuaternion base_to_world = body_->getWorldToBaseRot().inverse();
    rotation_[0] = from_bt(base_to_world);
    out.position[0] = from_bt(body_->getBasePos());
    out.orientation[0] = rotation_[0];
    out.velocity[0].setZero();
    out.angular[0].setZero();
    for (int i = 1; i < model_.count; ++i) {
      const int p = model_.parent[i];
      const int link = i - 1;
      // getParentToLocalRot: parent frame -> link frame; getRVector: parent COM -> link COM (link frame).
      const Quat this_to_parent = from_bt(body_->getParentToLocalRot(link)).conjugate();
      const Quat q = (rotation_[p] * this_to_parent).normalized();
      rotation_[i] = q;
      out.orientation[i] = q;
      out.position[i] = out.position[p] + q * from_bt(body_->getRVector(link));
      const btScalar* qdot = body_->getJointVelMultiDof(link);
      out.angular[i] = out.angular[p] + q * Vec3(qdot[0], qdot[1], qdot[2]);
    }
    set_velocities_keeping_joints(model_, out);
  }

 private:
  // One collider per component (link i - 1; the base for the hook) from its convex pieces.
  void add_colliders() {
    for (int i = 0; i < model_.count; ++i) {
      const internal::ComponentGeometry geometry = internal::build_component_geometry(model_.shapes[i]);
      auto compound = std::make_unique<btCompoundShape>();
      for (const internal::ConvexPiece& piece : geometry.pieces) {
        std::unique_ptr<btCollisionShape> shape;
        btTransform where = btTransform::getIdentity();
        switch (piece.kind) {
          case internal::ConvexPiece::Kind::Sphere:
            shape = std::make_unique<btSphereShape>(piece.radius);
            where.setOrigin(to_bt(piece.a));
            break;
          case internal::ConvexPiece::Kind::Cylinder: {
            const Vec3 axis = piece.b - piece.a;
            const double length = axis.norm();
            shape = std::make_unique<btCylinderShape>(btVector3(piece.radius, 0.5 * length, piece.radius));
            shape->setMargin(std::min(kHullMargin, 0.5 * piece.radius));
            where.setRotation(to_bt(Quat::FromTwoVectors(Vec3::UnitY(), axis / length)));
            where.setOrigin(to_bt(0.5 * (piece.a + piece.b)));
            break;
          }
          case internal::ConvexPiece::Kind::Polytope: {
            auto hull = std::make_unique<btConvexHullShape>();
            for (const Vec3& v : piece.vertices) hull->addPoint(to_bt(v), false);
            hull->recalcLocalAabb();
            hull->setMargin(kHullMargin);
            shape = std::move(hull);
            break;
          }
        }
        compound->addChildShape(where, shape.get());
        shapes_.push_back(std::move(shape));
      }
      auto collider = std::make_unique<btMultiBodyLinkCollider>(body_.get(), i - 1);
      collider->setCollisionShape(compound.get());
      collider->setRestitution(std::sqrt(model_.contact.restitution));  // the pair's: their product
      collider->setFriction(std::sqrt(model_.contact.friction));
      shapes_.push_back(std::move(compound));
      world_.addCollisionObject(collider.get(), btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter);
      if (i == 0) body_->setBaseCollider(collider.get());
      else body_->getLink(i - 1).m_collider = collider.get();
      colliders_.push_back(std::move(collider));
    }
    btAlignedObjectArray<btQuaternion> rotations;  // scratch for the colliders' first world transforms
    btAlignedObjectArray<btVector3> offsets;
    body_->updateCollisionObjectWorldTransforms(rotations, offsets);
  }

  const Model& model_;
  double timestep_;
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btMultiBodyConstraintSolver solver_;
  btMultiBodyDynamicsWorld world_;
  std::unique_ptr<btMultiBody> body_;
  std::vector<Quat> rotation_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;  // the compounds' children and the compounds
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  int points_ = 0;       // contact points after the last step
  double deepest_ = 0;   // m, the deepest overlap of any contact point so far
};

}  // namespace

std::unique_ptr<Engine> make_bullet(const Model& model, const State& initial, double timestep, bool collisions) {
  return std::make_unique<BulletEngine>(model, initial, timestep, collisions);
}

}  // namespace aloft::compare
