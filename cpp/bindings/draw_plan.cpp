// Context._last_draw_plan: the plan of the context's last draw (pipeline/draw_plan.h) as a dict,
// for gl.last_draw_plan() (python/softgl/context.py).
#include <pybind11/pybind11.h>

#include <string>

#include "exclusive.h"   // the Context caster every binding file shares
#include "softgl/api/context.h"
#include "softgl/pipeline/draw_plan.h"

namespace py = pybind11;

void bind_draw_plan(py::module_& m) {
    auto context = py::reinterpret_borrow<py::class_<softgl::Context>>(m.attr("Context"));
    context.def("_last_draw_plan", [](const softgl::Context& c) -> py::object {
        if (!c.last_draw_plan()) return py::none();
        const softgl::DrawPlan& plan = *c.last_draw_plan();
        py::dict d;
        for (const softgl::DrawPlanField& f : plan.fields()) {
            switch (f.kind) {
                case softgl::DrawPlanField::Bool: d[f.name] = f.value != 0; break;
                case softgl::DrawPlanField::Int: d[f.name] = f.value; break;
                case softgl::DrawPlanField::Name: d[f.name] = f.text; break;
                case softgl::DrawPlanField::PathKind:
                    d[f.name] = f.value == 0;
                    d[(std::string(f.name) + "_why_not").c_str()] = f.value == 0 ? py::object(py::none()) : py::str(f.text);
                    break;
            }
        }
        d["hash"] = plan.hash();
        d["text"] = plan.to_string();
        return d;
    });
}
