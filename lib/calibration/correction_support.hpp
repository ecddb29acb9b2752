// How far the data support a UMBmark correction (docs/safety.md, "Corrections
// the data cannot support"), computed from the summary's used runs:
//
//  - statistical: the standard errors of E_b and E_d from the return-error
//    scatter. The centre of gravity of each direction has covariance C/n
//    (C: the sample covariance of (ex, ey) about it, eq. 3.2); E_b and E_d
//    are smooth functions of the four centre coordinates (eqs. 4.20-4.27), so
//    Var(E) = sum over directions of g^T (C/n) g with g the gradient (delta
//    method, central differences). Intervals use Student t with
//    n_cw + n_ccw - 2 degrees of freedom.
//  - model: UMBmark's formulas are first order in alpha and beta (small
//    angles). The exact commanded-square model (model/commanded_square.hpp)
//    predicts the return errors of a robot with the estimated E_b, E_d; the
//    formulas applied to those give E_b', E_d', and E' - E is the
//    linearisation bias at this correction size.
//  - labels: to first order the cw centre lies on the line y = x and the ccw
//    centre on y = -x (x_cw = y_cw = -2L(alpha + beta), x_ccw = -y_ccw =
//    -2L(alpha - beta), from eqs. 4.20a/b, 4.24a/b). Reversed cw/ccw labels,
//    or swapped left/right encoder channels under a controller that closes
//    its loop on the (mirrored) odometry, put each centre on the other
//    diagonal.
#pragma once

#include "calibration/umbmark.hpp"

namespace umbmark {

struct CorrectionSupport {
  /// At least 2 used runs per direction: the scatter, hence everything
  /// statistical below, is known.
  bool scatter_known = false;
  double se_E_b = 0.0, se_E_d = 0.0;  ///< delta-method standard errors
  double t95 = 0.0;                    ///< Student t 0.975 quantile, n_cw + n_ccw - 2 dof
  double bias_E_b = 0.0, bias_E_d = 0.0;  ///< E' - E, the first-order formulas' bias at E
  /// Squared distance of the two centres from the diagonals their labels
  /// predict, and from the other diagonals [m^2].
  double off_labels_m2 = 0.0, off_reversed_m2 = 0.0;
  /// p-value of the centres' distance from their own diagonals: per
  /// direction a two-sided Student t test (n - 1 dof) of the off-diagonal
  /// component, combined by Fisher's method (chi-square, 4 dof); 1 when the
  /// scatter is unknown.
  double p_off_labels = 1.0;
};

/// Precondition: s comes from CalibrateUmbmark (cw and ccw have used runs).
CorrectionSupport AnalyseCorrectionSupport(const UmbmarkSummary& s);

/// The 95 % half-width of E_b or E_d from a CorrectionSupport's se.
inline double HalfWidth95(const CorrectionSupport& c, double se) { return c.t95 * se; }

}  // namespace umbmark
