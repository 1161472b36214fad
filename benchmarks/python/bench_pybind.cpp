// The pybind11 side of bench_binding.py: the same library calls as the cffi side, compiled
// as an extension module, to compare call overhead and zero-copy array views.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

extern "C" {
#include "cadmorph/mesh.h"
}

namespace py = pybind11;

struct Mesh {
    cm_mesh *m = nullptr;
    explicit Mesh(const std::string &path)
    {
        cm_context *ctx = nullptr;
        if (cm_context_create(&ctx) != CM_OK) throw std::bad_alloc();
        cm_status s = cm_mesh_read(ctx, path.c_str(), &m);
        std::string msg = cm_context_message(ctx);
        cm_context_destroy(&ctx);
        if (s < 0) throw std::runtime_error(msg);
    }
    ~Mesh() { cm_mesh_destroy(&m); }
};

PYBIND11_MODULE(cm_pybind, mod)
{
    mod.def("cell_nodes", [](int t) { return cm_cell_type_info((cm_cell_type)t)->nodes; });
    mod.def("format_list", []() { return std::string(cm_mesh_format_list()); });
    py::class_<Mesh>(mod, "Mesh")
        .def(py::init<const std::string &>())
        // a view onto xyz whose base is the Mesh: no copy, the mesh lives while the array does
        .def("points", [](py::object self) {
            Mesh &me = self.cast<Mesh &>();
            return py::array_t<double>({(py::ssize_t)me.m->n_nodes, (py::ssize_t)3}, me.m->xyz,
                                       self);
        });
}
