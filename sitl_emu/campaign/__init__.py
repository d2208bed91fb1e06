"""Campaigns: one scenario flown over many cases (seeds, parameters, timed faults, options), one table back.

    from sitl_emu.campaign import Outcome, make_cases, run_campaign

    def fly(sim, case):                       # a scenario: the user's client against an in-process Sim
        ...
        return Outcome(passed=error_m < 1.0, metrics={"max_error_m": error_m})

    cases = make_cases(grid={"params.SIH_WIND_N": [0.0, 5.0]}, draws={"seed": {"integers": [0, 10**6]}}, count=10)
    print(run_campaign(fly, cases, "results.csv").text())

`sitl-emu campaign` is the same from the command line (campaign/cli.py); the file format is in spec.py, the
columns in results.py, the engines in engines/.
"""

from sitl_emu.campaign.cases import Case, FaultDraw, make_cases
from sitl_emu.campaign.errors import CampaignError, CampaignInterrupted, CaseError
from sitl_emu.campaign.faults import Fault, FaultSchedule, parse_fault
from sitl_emu.campaign.run import run_campaign
from sitl_emu.campaign.scenario import Limits, Outcome, run_case
from sitl_emu.campaign.spec import CampaignSpec, read_spec
from sitl_emu.campaign.summary import Summary

__all__ = ["CampaignError", "CampaignInterrupted", "CampaignSpec", "Case", "CaseError", "Fault", "FaultDraw",
           "FaultSchedule", "Limits", "Outcome", "Summary", "make_cases", "parse_fault", "read_spec", "run_campaign",
           "run_case"]
