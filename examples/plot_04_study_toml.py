"""
A parameter study from TOML
===========================

A study is data: a base parameter set, one or two axes and a list of analyses. This one
varies the CoM offset ``r`` of the passive model (thesis Figure 4.15, coarsely) and
plots the largest non-trivial multiplier along it.
"""

# %%
import tempfile
from pathlib import Path

from tslip.plotting.studies import plot_study_multipliers
from tslip.sweeps import StudySpec, run_study

spec_text = """
name = "mass-offset"
preset = "table2.1"
analyses = ["floquet"]
[[axis]]
param = "r"
from = 0.0
to = 1.0
points = 9
"""
folder = Path(tempfile.mkdtemp())
(folder / "mass-offset.toml").write_text(spec_text)
spec = StudySpec.from_toml(folder / "mass-offset.toml")
result = run_study(spec, folder / "out", workers=1)    # cached and resumable in out/cache
print(result.frame[["r", "max_nontrivial", "stability"]].to_string(index=False))
fig = plot_study_multipliers(result)   # fig.savefig("mass_offset.png") writes it
