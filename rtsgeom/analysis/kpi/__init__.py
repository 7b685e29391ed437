"""The setup's datasheet: test-device KPIs with an uncertainty budget, checked against a spec
(``rtsgeom kpi``).

:class:`KpiStudy` (:mod:`.study`) called on a scene returns a :class:`Datasheet`: the field of
view, the angle accuracy over it with its GUM budget validated by a Monte Carlo
(:mod:`.accuracy`, :mod:`.budget`), range and velocity, targets, ghosts and leakage, the near
field (:mod:`.sections`), checked against a :class:`KpiSpec` (:mod:`.spec`);
:func:`.headline.headline` makes its key KPIs for every view; :mod:`.report` writes its HTML
page and PDF.
"""

from .budget import BudgetRow
from .spec import KpiSpec, SpecCheck, check_spec, load_spec, loads_spec
from .study import Datasheet, KpiStudy

__all__ = ["KpiStudy", "Datasheet", "KpiSpec", "SpecCheck", "BudgetRow", "load_spec",
           "loads_spec", "check_spec"]
