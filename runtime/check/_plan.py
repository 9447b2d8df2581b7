class CheckPlan: pass
def plan_check(): pass
