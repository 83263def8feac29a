"""Heat conduction: an insulated pipe. A steel pipe (inner radius 0.1 m, outer 0.15 m,
k = 15 W/(m K)) in a layer of insulation (out to 0.25 m, k = 0.8 W/(m K)) carries a fluid
at 150 °C; the outside loses heat to air at 20 °C by convection, h = 10 W/(m^2 K).

The exact solution is radial: the heat per unit length Q = (T_i - T_inf) / (R1 + R2 + Rc)
through the series of resistances R_j = ln(r_{j+1} / r_j) / (2 pi k_j) and
Rc = 1 / (2 pi r_2 h), and T(r) falls by Q ln(r / r_j) / (2 pi k_j) across layer j.
``python docs/examples/heat_pipe.py`` prints the errors and draws the temperature.
"""

import pathlib

import numpy as np

import cnem

R0, R1, R2 = 0.10, 0.15, 0.25                 # m
K1, K2 = 15.0, 0.8                            # W/(m K)
T_IN, T_AIR, H = 150.0, 20.0, 10.0            # °C, °C, W/(m^2 K)


def exact():
    """The radial solution: heat per unit length Q (W/m), T(x) and grad T(x)."""
    resistance = [np.log(R1 / R0) / (2 * np.pi * K1), np.log(R2 / R1) / (2 * np.pi * K2)]
    q = (T_IN - T_AIR) / (sum(resistance) + 1 / (2 * np.pi * R2 * H))

    def temperature(x):
        r = np.hypot(x[:, 0], x[:, 1])
        inner = T_IN - q * np.log(r / R0) / (2 * np.pi * K1)
        outer = T_IN - q * resistance[0] - q * np.log(r / R1) / (2 * np.pi * K2)
        return np.where(r <= R1, inner, outer)

    def gradient(x):
        r = np.hypot(x[:, 0], x[:, 1])
        k = np.where(r <= R1, K1, K2)
        return (-q / (2 * np.pi * k * r ** 2))[:, None] * x
    return q, temperature, gradient


def main(h=0.006, outdir="docs/images", plot=True):
    """Solve on nodes about ``h`` apart; returns the errors against the exact solution."""
    dom = cnem.geometry.annulus([R0, R1, R2], spacing=h)       # regions: steel, insulation
    model = cnem.discretize(cnem.nodes.irregular(dom, h, seed=0))
    prob = cnem.HeatConduction(model, [K1, K2])
    prob.add_temperature("inner", T_IN)
    prob.add_convection("outer", h=H, ambient=T_AIR)
    sol = prob.solve()
    q, temperature, gradient = exact()
    out = {"nodes": len(model.nodes),
           "T_error_max": float(np.abs(sol.T - temperature(model.nodes)).max()),
           "h1_error_relative": sol.h1_error(gradient) / sol.h1_error(lambda x: 0 * x),
           "Q_exact": float(q)}
    outer = model.domain.on_boundary(model.nodes, "outer")
    out["T_surface"], out["T_surface_exact"] = float(sol.T[outer].mean()), \
        float(temperature(model.nodes[outer][:1])[0])
    # the heat leaving by convection, per unit length: h (T - T_air) along the outer edges
    edges, _ = prob.boundary_edges()
    edges = edges[outer[edges].all(axis=1)]
    length = np.linalg.norm(np.diff(model.nodes[edges], axis=1)[:, 0], axis=1)
    out["Q"] = float(H * (length * (sol.T[edges].mean(axis=1) - T_AIR)).sum())
    if plot:
        path = pathlib.Path(outdir) / "heat_pipe_temperature.png"
        sol.plot(path, title="T (°C)", length_unit="m").close()
        out["picture"] = str(path)
    return out


if __name__ == "__main__":
    for key, value in main().items():
        print(f"{key:>20}: {value:.6g}" if isinstance(value, float) else f"{key:>20}: {value}")
