"""
A study on a Dask cluster
=========================

Studies run on the local cores by default; with ``scheduler=`` they run on a Dask
cluster instead (``pip install "tslip[dask]"``). Here the cluster is a local one started
by the script, standing in for a real scheduler address such as
``tcp://10.0.0.5:8786``. The points are the same, computed elsewhere.
"""

# %%
import numpy as np

import tslip
from tslip.plotting.studies import plot_study_multipliers
from tslip.sweeps import Axis, StudySpec, run_study

spec = StudySpec("retraction", tslip.preset("table2.1"),
                 axes=(Axis("omega_r", tuple(np.linspace(0.0, 2.0, 6))),),
                 analyses=("floquet",))

if __name__ == "__main__":
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None, silence_logs="error") as cluster:
        result = run_study(spec, scheduler=cluster.scheduler_address)
    print(result.frame[["omega_r", "max_nontrivial", "stability"]].to_string(index=False))
    fig = plot_study_multipliers(result)   # fig.savefig("retraction.png") writes it
