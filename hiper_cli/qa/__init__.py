"""A question-answering benchmark with ground truth (``hiper eval qa``): NaVQA-style questions
generated from a log's truth, asked through the query layer, scored per kind and horizon."""

from hiper_cli.qa.questions import KINDS, Question, generate_questions
from hiper_cli.qa.run import QaReport, QaSet, evaluate_qa, evaluate_qa_set
from hiper_cli.qa.scene import SceneTruth, load_scene_truth
from hiper_cli.qa.score import Scored, answer_question, summarise

__all__ = ["KINDS", "QaReport", "QaSet", "Question", "SceneTruth", "Scored", "answer_question", "evaluate_qa",
           "evaluate_qa_set", "generate_questions", "load_scene_truth", "summarise"]
