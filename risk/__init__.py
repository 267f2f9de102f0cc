# C&C driver model, Preventable boundaries and UN R157 test points (JAMA 2.3.3, Annex G)
from hiyari.risk.cc.boundary import cut_in_boundary as cut_in_boundary
from hiyari.risk.cc.boundary import cut_out_boundary as cut_out_boundary
from hiyari.risk.cc.boundary import decel_boundary_gap as decel_boundary_gap
from hiyari.risk.cc.evaluator import CCResult as CCResult
from hiyari.risk.cc.evaluator import evaluate_cut_in as evaluate_cut_in
from hiyari.risk.cc.evaluator import evaluate_cut_out as evaluate_cut_out
from hiyari.risk.cc.evaluator import evaluate_decel as evaluate_decel
from hiyari.risk.cc.model import CCParams as CCParams
from hiyari.risk.cc.r157_points import R157Config as R157Config
from hiyari.risk.cc.r157_points import R157Point as R157Point
from hiyari.risk.cc.r157_points import generate_points as generate_points
from hiyari.risk.cc.r157_points import load_points as load_points
