% Driver of benchmarks/bench_nlvib.py, case 1: NLvib's solve_and_continue on rattle's reference clutch.
%   nlvib_clutch(nlvib, p, H, N, Om_s, Om_e, ds, dsmin, repeats, outfile)
% p: struct of I, c, k, alpha, b, Fm, Fp. Times the continuation only (tic/toc and cputime, every
% repeat); writes to outfile: line 1 the wall times, line 2 the CPU times (s), then one solution
% point per line: [a0 a1 b1 ... aH bH Om].
function nlvib_clutch(nlvib, p, H, N, Om_s, Om_e, ds, dsmin, repeats, outfile)
addpath(fullfile(nlvib, 'SRC'));
tau = 2 * pi * (0:N-1)' / N;
E = ones(N, 2 * H + 1);
w = ones(1, 2 * H + 1) / N;
for h = 1:H
  E(:, 2 * h) = cos(h * tau);
  E(:, 2 * h + 1) = sin(h * tau);
  w([2 * h, 2 * h + 1]) = 2 / N;
end
P = (E .* w)';
% initial guess: the linear solution (stiffness k) about the static deflection, as NLvib's examples start
x0 = zeros(2 * H + 1, 1);
x0(1) = p.Fm / p.k;
Q = p.Fp / (-Om_s^2 * p.I + 1i * Om_s * p.c + p.k);
x0(2) = real(Q); x0(3) = -imag(Q);
Sopt = struct('dsmin', dsmin);  % everything else NLvib's defaults (arc length, tangent predictor, dsmax = 5 ds)
% NLvib's default solver options (solve_and_continue.m), written with optimset('fsolve'): Octave's
% optimset does not take the function handle @fsolve that NLvib's default line passes.
Solopt = optimset(optimset('fsolve'), 'Display', 'off', 'Jacobian', 'on', 'MaxIter', 50);
fun = @(X) clutch_residual(X, p, E, P);
walls = zeros(1, repeats); cpus = zeros(1, repeats);
for r = 1:repeats
  c0 = cputime; t0 = tic;
  X = solve_and_continue(x0, fun, Om_s, Om_e, ds, Sopt, {}, Solopt);
  walls(r) = toc(t0); cpus(r) = cputime - c0;
end
fid = fopen(outfile, 'w');
fprintf(fid, '%.9g ', walls); fprintf(fid, '\n');
fprintf(fid, '%.9g ', cpus); fprintf(fid, '\n');
fclose(fid);
dlmwrite(outfile, X', '-append', 'delimiter', ' ', 'precision', '%.17g');
end
