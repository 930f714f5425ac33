"""Multiple importance sampling (compendium items 27–28; Veach and Guibas 1995).

Technique j draws N_j = c_j N samples from p_j. With q_j = N_j p_j(x), the power
heuristic is w_j = q_j^β / Σ_k q_k^β; β = 1 is the balance heuristic, β = 2 the usual
power heuristic, β → ∞ the maximum heuristic and β = 0 gives equal weights to every
technique that can produce x. Weights are computed from ratios q_k / q_j so large β
and large pdfs cannot overflow.

Delta techniques (item 1): a Dirac sample carries pdf = inf (see warps.py). Its MIS
weight is 1, since no other technique can produce its direction, and a delta technique
contributes nothing to other techniques' weights (its density elsewhere is 0). A
technique with p_j(x) = 0 gets weight 0. Weights of the techniques that can produce
x sum to 1, which keeps the combined estimator unbiased (item 27).
"""
import math

import numpy as np

from ..jit import inline


@inline
def mis_weight(n_a, pdf_a, n_b, pdf_b, beta):
    """Weight of technique a (n_a samples, density pdf_a at x) against technique b."""
    if pdf_a == math.inf:
        return 1.0
    if pdf_b == math.inf:
        return 0.0
    qa = n_a * pdf_a
    qb = n_b * pdf_b
    if not (qa > 0.0):
        return 0.0
    if not (qb > 0.0):
        return 1.0
    r = qb / qa
    if beta == math.inf:
        if r < 1.0:
            return 1.0
        if r > 1.0:
            return 0.0
        return 0.5
    if beta == 1.0:
        return 1.0 / (1.0 + r)
    if beta == 2.0:
        return 1.0 / (1.0 + r * r)
    return 1.0 / (1.0 + r ** beta)


@inline
def balance_heuristic(n_a, pdf_a, n_b, pdf_b):
    return mis_weight(n_a, pdf_a, n_b, pdf_b, 1.0)


@inline
def power_heuristic(n_a, pdf_a, n_b, pdf_b):
    return mis_weight(n_a, pdf_a, n_b, pdf_b, 2.0)


@inline
def mis_weight_k(i, counts, pdfs, k, beta):
    """Weight of technique i among k techniques (arrays ``counts`` and ``pdfs`` of length ≥ k)."""
    if pdfs[i] == math.inf:
        return 1.0
    qi = counts[i] * pdfs[i]
    if not (qi > 0.0):
        return 0.0
    s = 1.0
    for j in range(k):
        if j == i:
            continue
        if pdfs[j] == math.inf:
            return 0.0
        qj = counts[j] * pdfs[j]
        if qj > 0.0:
            r = qj / qi
            if beta == math.inf:
                if r > 1.0:
                    return 0.0
                if r == 1.0:
                    s += 1.0
            else:
                s += r ** beta
    return 1.0 / s


# -- NumPy helpers ------------------------------------------------------------------

def mis_weights(pdfs, counts=None, beta=2.0):
    """Weights (k, ...) for the densities ``pdfs`` (k, ...) of k techniques at the same points.

    Columns where no technique has a positive density get all-zero weights; a column with
    a Dirac (inf) gives weight 1 to the Dirac technique(s), shared equally.
    """
    p = np.asarray(pdfs, dtype=np.float64)
    k = p.shape[0]
    c = np.ones(k) if counts is None else np.asarray(counts, dtype=np.float64)
    q = p * c.reshape((k,) + (1,) * (p.ndim - 1))
    delta = np.isinf(q)
    nd = delta.sum(axis=0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if beta == np.inf:
            qmax = q.max(axis=0)
            top = (q == qmax) & (q > 0)
            w = top / np.maximum(top.sum(axis=0), 1)
        else:
            qmax = np.where(np.isfinite(q), q, 0.0).max(axis=0)
            safe = np.where(qmax > 0, qmax, 1.0)
            r = np.where(q > 0, q / safe, 0.0)
            rb = np.where(r > 0, r ** beta, 0.0)
            s = rb.sum(axis=0)
            w = np.where(s > 0, rb / np.where(s > 0, s, 1.0), 0.0)
        w = np.where(nd > 0, delta / np.maximum(nd, 1), w)
    return w


def combine_multi_sample(f_values, pdf_tables, counts, beta=2.0):
    """Multi-sample MIS estimate Σ_j (1/N_j) Σ_i w_j(x_ij) f(x_ij) / p_j(x_ij) (item 27).

    f_values[j]: (N_j,) integrand at technique j's samples; pdf_tables[j]: (k, N_j) the
    densities of all k techniques at those samples; counts: N_j. Dirac samples (pdf inf)
    must hold the discrete weight f/P in f_values[j] and are counted with weight 1.
    """
    counts = np.asarray(counts, dtype=np.float64)
    total = 0.0
    for j, (f, pt) in enumerate(zip(f_values, pdf_tables)):
        f = np.asarray(f, dtype=np.float64)
        pt = np.asarray(pt, dtype=np.float64)
        w = mis_weights(pt, counts, beta)[j]
        pj = pt[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            contrib = np.where(np.isinf(pj), w * f, np.where(pj > 0, w * f / np.where(pj > 0, pj, 1.0), 0.0))
        total += contrib.sum() / counts[j]
    return total


def combine_one_sample(f, pdfs, chosen, probs, beta=1.0):
    """One-sample MIS (item 28): technique ``chosen[i]`` was picked with probability
    probs[chosen[i]] and drew x_i. Returns the per-sample estimates
    w_c(x) f(x) / (c_c p_c(x)) with weights from c_j p_j(x); their mean estimates ∫ f.
    The balance heuristic (β = 1) is the optimal choice in this setting."""
    f = np.asarray(f, dtype=np.float64)
    p = np.asarray(pdfs, dtype=np.float64)
    chosen = np.asarray(chosen, dtype=np.int64)
    probs = np.asarray(probs, dtype=np.float64)
    w = mis_weights(p, probs, beta)
    idx = np.arange(f.shape[0])
    wc = w[chosen, idx]
    pc = p[chosen, idx] * probs[chosen]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.isinf(pc), wc * f / probs[chosen],
                        np.where(pc > 0, wc * f / np.where(pc > 0, pc, 1.0), 0.0))
