% Harmonic-balance residual of rattle's reference clutch for NLvib's solve_and_continue
% (written for benchmarks/bench_nlvib.py; the pattern of NLvib's EXAMPLES/01_Duffing/HB_residual_Duffing.m,
% alternating frequency/time, with the analytical Jacobian that NLvib's own HB_residual.m provides):
%
%   I d'' + c d' + k f(d) = Fm + Fp cos(Om t),
%   f(d) = alpha d (|d| <= b),  d - (1 - alpha) b sign(d) (|d| > b)   (two-stage clutch damper).
%
% X = [a0; a1; b1; a2; b2; ...; aH; bH; Om] (NLvib's sine-cosine order), d = a0 + sum a_h cos(h tau) + b_h sin(h tau).
% E (N x 2H+1): the basis sampled at tau_j = 2 pi j / N; P (2H+1 x N): the discrete Fourier projection.
% Returns R (2H+1) and dR = [dR/dx, dR/dOm] (2H+1 x 2H+2), as NLvib's Sopt.jac = 'full' expects.
function [R, dR] = clutch_residual(X, p, E, P)
H = (length(X) - 2) / 2;
x = X(1:end-1);
Om = X(end);
% time domain: the clutch law and its slope at the samples
d = E * x;
outside = abs(d) > p.b;
f = p.alpha * d;
f(outside) = d(outside) - (1 - p.alpha) * p.b * sign(d(outside));
kt = p.alpha * ones(size(d));
kt(outside) = 1;
Fnl = p.k * (P * f);
dFnl = p.k * (P * (kt .* E));
% linear part, harmonic by harmonic: cos: -I (h Om)^2 a_h + c h Om b_h; sin: -I (h Om)^2 b_h - c h Om a_h
h = (1:H)';
ic = 2 * h; is = 2 * h + 1;
L = zeros(2 * H + 1);
dL = zeros(2 * H + 1, 1);
L(sub2ind(size(L), ic, ic)) = -p.I * (h * Om).^2;
L(sub2ind(size(L), is, is)) = -p.I * (h * Om).^2;
L(sub2ind(size(L), ic, is)) = p.c * h * Om;
L(sub2ind(size(L), is, ic)) = -p.c * h * Om;
dL(ic) = -2 * p.I * h.^2 * Om .* x(ic) + p.c * h .* x(is);
dL(is) = -2 * p.I * h.^2 * Om .* x(is) - p.c * h .* x(ic);
Fex = zeros(2 * H + 1, 1);
Fex(1) = p.Fm;
Fex(2) = p.Fp;
R = L * x + Fnl - Fex;
dR = [L + dFnl, dL];
end
