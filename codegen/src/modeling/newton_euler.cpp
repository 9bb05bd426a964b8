#include "newton_euler.hpp"

namespace symoro::codegen::modeling {

Vec3 add(ExprGraph& g, const Vec3& a, const Vec3& b) {
  return {g.add(a[0], b[0]), g.add(a[1], b[1]), g.add(a[2], b[2])};
}
Vec3 sub(ExprGraph& g, const Vec3& a, const Vec3& b) {
  return {g.sub(a[0], b[0]), g.sub(a[1], b[1]), g.sub(a[2], b[2])};
}
Vec3 scale(ExprGraph& g, NodeId s, const Vec3& a) { return {g.mul(s, a[0]), g.mul(s, a[1]), g.mul(s, a[2])}; }
Vec3 cross(ExprGraph& g, const Vec3& a, const Vec3& b) {
  return {g.sub(g.mul(a[1], b[2]), g.mul(a[2], b[1])), g.sub(g.mul(a[2], b[0]), g.mul(a[0], b[2])),
          g.sub(g.mul(a[0], b[1]), g.mul(a[1], b[0]))};
}
NodeId dot(ExprGraph& g, const Vec3& a, const Vec3& b) {
  return g.add(g.add(g.mul(a[0], b[0]), g.mul(a[1], b[1])), g.mul(a[2], b[2]));
}
Vec3 times(ExprGraph& g, const Mat3& R, const Vec3& v) { return {dot(g, R[0], v), dot(g, R[1], v), dot(g, R[2], v)}; }
Vec3 transpose_times(ExprGraph& g, const Mat3& R, const Vec3& v) {
  Vec3 out;
  for (int c = 0; c < 3; ++c) out[c] = g.add(g.add(g.mul(R[0][c], v[0]), g.mul(R[1][c], v[1])), g.mul(R[2][c], v[2]));
  return out;
}
Mat3 times(ExprGraph& g, const Mat3& A, const Mat3& B) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[r][c] = g.add(g.add(g.mul(A[r][0], B[0][c]), g.mul(A[r][1], B[1][c])), g.mul(A[r][2], B[2][c]));
  return out;
}

namespace {

Mat3 rot_z(ExprGraph& g, NodeId a) {
  const NodeId c = exact_cos(g, a), s = exact_sin(g, a), z = g.zero(), o = g.one();
  return {Vec3{c, g.neg(s), z}, Vec3{s, c, z}, Vec3{z, z, o}};
}
Mat3 rot_x(ExprGraph& g, NodeId a) {
  const NodeId c = exact_cos(g, a), s = exact_sin(g, a), z = g.zero(), o = g.one();
  return {Vec3{o, z, z}, Vec3{z, c, g.neg(s)}, Vec3{z, s, c}};
}

}  // namespace

Transform frame_transform(ExprGraph& g, const JointDescription& j, NodeId theta, NodeId r) {
  const Mat3 Rg = rot_z(g, j.gamma_n);
  Transform t;
  t.R = times(g, times(g, Rg, rot_x(g, j.alpha_n)), rot_z(g, theta));
  const NodeId ca = exact_cos(g, j.alpha_n), sa = exact_sin(g, j.alpha_n);
  t.p = times(g, Rg, Vec3{j.d_n, g.neg(g.mul(r, sa)), g.add(j.b_n, g.mul(r, ca))});
  return t;
}

Transform joint_transform(ExprGraph& g, const JointDescription& j) { return frame_transform(g, j, j.theta_n, j.r_n); }

std::vector<NodeId> inverse_dynamics(ExprGraph& g, const Description& d, const std::vector<LinkParameters>& links) {
  const int n = d.n;
  const NodeId z = g.zero();
  const Vec3 zero{z, z, z};
  std::vector<Transform> T(n);
  std::vector<Vec3> w(n + 1, zero), wp(n + 1, zero), vp(n + 1, zero), f(n + 1, zero), m(n + 1, zero);
  // The base's acceleration is -G: gravity as a fictitious acceleration of the whole robot.
  vp[0] = {g.neg(d.gravity[0]), g.neg(d.gravity[1]), g.neg(d.gravity[2])};
  for (int j = 1; j <= n; ++j) {
    const JointDescription& jd = d.joints[j - 1];
    const LinkParameters& k = links[j - 1];
    T[j - 1] = joint_transform(g, jd);
    const Transform& t = T[j - 1];
    const int i = jd.ant;
    const NodeId qd = g.symbol(jd.qd), qdd = g.symbol(jd.qdd);
    const Vec3 wi = transpose_times(g, t.R, w[i]);  // jR_i w_i
    // Acceleration of O_j carried by link i, in frame j.
    vp[j] = transpose_times(g, t.R, add(g, vp[i], add(g, cross(g, wp[i], t.p), cross(g, w[i], cross(g, w[i], t.p)))));
    wp[j] = transpose_times(g, t.R, wp[i]);
    w[j] = wi;
    if (jd.sigma == 0) {
      w[j][2] = g.add(w[j][2], qd);
      wp[j][2] = g.add(wp[j][2], qdd);
      // + (jR_i w_i) x (qd z) = qd (wi_y, -wi_x, 0)
      wp[j][0] = g.add(wp[j][0], g.mul(wi[1], qd));
      wp[j][1] = g.sub(wp[j][1], g.mul(wi[0], qd));
    } else {
      vp[j][2] = g.add(vp[j][2], qdd);
      // + 2 (jR_i w_i) x (qd z)
      const NodeId two_qd = g.mul(g.constant(2.0), qd);
      vp[j][0] = g.add(vp[j][0], g.mul(wi[1], two_qd));
      vp[j][1] = g.sub(vp[j][1], g.mul(wi[0], two_qd));
    }
    const auto& P = k.inertial;
    const Vec3 ms{P[MX], P[MY], P[MZ]};
    const Mat3 J{Vec3{P[XX], P[XY], P[XZ]}, Vec3{P[XY], P[YY], P[YZ]}, Vec3{P[XZ], P[YZ], P[ZZ]}};
    // F_j = M vp + wp x MS + w x (w x MS);  N_j = J wp + w x (J w) + MS x vp
    f[j] = add(g, scale(g, P[M], vp[j]), add(g, cross(g, wp[j], ms), cross(g, w[j], cross(g, w[j], ms))));
    m[j] = add(g, times(g, J, wp[j]), add(g, cross(g, w[j], times(g, J, w[j])), cross(g, ms, vp[j])));
  }
  std::vector<NodeId> tau(n);
  for (int j = n; j >= 1; --j) {
    const JointDescription& jd = d.joints[j - 1];
    const LinkParameters& k = links[j - 1];
    const NodeId qd = g.symbol(jd.qd), qdd = g.symbol(jd.qdd);
    NodeId t = jd.sigma == 0 ? m[j][2] : f[j][2];
    t = g.add(t, g.mul(k.ia, qdd));
    t = g.add(t, g.mul(k.fv, qd));
    t = g.add(t, g.mul(k.fs, g.sign(qd)));
    tau[j - 1] = t;
    // The link's wrench goes to its antecedent: f_i += iR_j f_j, m_i += iR_j m_j + iP_j x (iR_j f_j).
    const int i = jd.ant;
    if (i == 0) continue;
    const Transform& tr = T[j - 1];
    const Vec3 fi = times(g, tr.R, f[j]);
    f[i] = add(g, f[i], fi);
    m[i] = add(g, m[i], add(g, times(g, tr.R, m[j]), cross(g, tr.p, fi)));
  }
  return tau;
}

namespace {

// 0 T j for every frame on the way (index j, 0 = identity).
std::vector<Transform> absolute_frames(ExprGraph& g, const Description& d) {
  const NodeId z = g.zero(), o = g.one();
  std::vector<Transform> out(d.n + 1);
  out[0] = {Mat3{Vec3{o, z, z}, Vec3{z, o, z}, Vec3{z, z, o}}, Vec3{z, z, z}};
  for (int j = 1; j <= d.n; ++j) {
    const Transform t = joint_transform(g, d.joints[j - 1]);
    const Transform& a = out[d.joints[j - 1].ant];
    out[j] = {times(g, a.R, t.R), add(g, a.p, times(g, a.R, t.p))};
  }
  return out;
}

}  // namespace

std::array<std::array<NodeId, 4>, 3> frame_pose(ExprGraph& g, const Description& d, int f) {
  const Transform t = absolute_frames(g, d)[f];
  std::array<std::array<NodeId, 4>, 3> out;
  for (int r = 0; r < 3; ++r) out[r] = {t.R[r][0], t.R[r][1], t.R[r][2], t.p[r]};
  return out;
}

std::vector<std::vector<NodeId>> frame_jacobian(ExprGraph& g, const Description& d, int f) {
  const auto frames = absolute_frames(g, d);
  std::vector<std::vector<NodeId>> J(6, std::vector<NodeId>(d.n, g.zero()));
  const Vec3& pn = frames[f].p;
  for (int j = f; j >= 1; j = d.joints[j - 1].ant) {
    const Transform& fr = frames[j];
    const Vec3 a{fr.R[0][2], fr.R[1][2], fr.R[2][2]};  // the joint axis z_j in frame 0
    if (d.joints[j - 1].sigma == 0) {
      const Vec3 v = cross(g, a, sub(g, pn, fr.p));
      for (int r = 0; r < 3; ++r) {
        J[r][j - 1] = v[r];
        J[3 + r][j - 1] = a[r];
      }
    } else {
      for (int r = 0; r < 3; ++r) J[r][j - 1] = a[r];
    }
    if (d.joints[j - 1].ant == 0) break;
  }
  return J;
}

}  // namespace symoro::codegen::modeling
