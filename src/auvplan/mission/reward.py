r"""Terrain information inside the optimiser: a reward on the information map's spline surface.

With ``S`` the C² cubic B-spline surface of the information map (eq. 13;
:class:`auvplan.terrain.spline.SplineSurface`) the running cost gains, per vehicle ``i``,

.. math::

    r(x) = -c \sum_i S(n_i, e_i), \qquad c = w_T\, w_I \;[\mathrm{W}],

charged at the solver nodes (``dt Σ_k r(x_k)``, a :class:`auvplan.optimization.NodeCost`):
``w_T`` is the terrain weight and ``w_I`` (``[weights] information``) the power a vehicle would
spend to stay over fully informative terrain. The optimiser may then leave the desired path
where the information gained pays for the extra energy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from auvplan._typing import FloatArray, IntArray
from auvplan.mission.fleet import FleetLayout
from auvplan.terrain import TerrainMaps
from auvplan.terrain.spline import SplineSurface

__all__ = ["InformationReward", "information_reward"]


@dataclass(frozen=True, eq=False)
class InformationReward:
    """The node cost ``r(x) = −c Σ_i S(n_i, e_i)`` (module equations).

    ``positions`` ``(n_vehicles, 2)``: rows of each vehicle's north and east in the stacked
    state of size ``n_x``; ``weight`` is ``c`` [W].
    """

    surface: SplineSurface
    positions: IntArray
    weight: float
    n_x: int

    def _surface(self, states: FloatArray) -> FloatArray:
        """``(S, S_n, S_e, S_nn, S_ne, S_ee)`` of every vehicle, shape ``(n_vehicles, N, 6)``."""
        return np.stack(
            [self.surface.evaluate(states[:, n], states[:, e]) for n, e in self.positions]
        )

    def values(self, states: FloatArray) -> FloatArray:
        """``r(x_k)`` [W], shape ``(N,)``."""
        total: FloatArray = -self.weight * np.sum(self._surface(states)[..., 0], axis=0)
        return total

    def derivatives(self, states: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``r`` ``(N,)``, ``∇r`` ``(N, n_x)`` and ``∇²r`` ``(N, n_x, n_x)`` (exact)."""
        surface = -self.weight * self._surface(states)
        n_stages = states.shape[0]
        gradient = np.zeros((n_stages, self.n_x))
        hessian = np.zeros((n_stages, self.n_x, self.n_x))
        for (n, e), values in zip(self.positions, surface, strict=True):
            gradient[:, n], gradient[:, e] = values[:, 1], values[:, 2]
            hessian[:, n, n], hessian[:, e, e] = values[:, 3], values[:, 5]
            hessian[:, n, e] = hessian[:, e, n] = values[:, 4]
        return np.sum(surface[..., 0], axis=0), gradient, hessian


def information_reward(
    layout: FleetLayout, maps: TerrainMaps, weight: float
) -> InformationReward | None:
    """The reward of every vehicle of ``layout`` over ``maps`` (``None`` when ``weight`` is 0)."""
    if weight <= 0.0:
        return None
    positions = np.array(
        [
            [layout.state_slice(i).start + model.index(name) for name in ("north", "east")]
            for i, model in enumerate(layout.models)
        ],
        dtype=np.int64,
    )
    surface = SplineSurface.fit(maps.bathymetry.geometry, maps.information)
    return InformationReward(surface, positions, float(weight), layout.n_x)
