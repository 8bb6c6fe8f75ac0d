/* See vts_readback.h. */
#include "vts_readback.h"

#include <vtkDataArray.h>
#include <vtkDataSetAttributes.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStructuredGrid.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLStructuredGridReader.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

int vts_read(const char *path, const char *field_name, vts_data *out)
{
    std::memset(out, 0, sizeof *out);
    try {
        auto reader = vtkSmartPointer<vtkXMLStructuredGridReader>::New();
        if (!reader->CanReadFile(path)) {
            std::snprintf(out->error, sizeof out->error, "VTK cannot read '%s'", path);
            return -1;
        }
        reader->SetFileName(path);
        reader->Update();
        vtkStructuredGrid *grid = reader->GetOutput();
        grid->GetDimensions(out->dims);
        out->n_points = (long)grid->GetNumberOfPoints();
        grid->GetBounds(out->bounds);
        out->xyz = (double *)std::malloc(sizeof(double) * 3 * (size_t)out->n_points);
        for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
            grid->GetPoint(i, &out->xyz[3 * i]);
        if (vtkUnsignedCharArray *ghosts = grid->GetPointGhostArray())
            for (vtkIdType i = 0; i < ghosts->GetNumberOfTuples(); ++i)
                if (ghosts->GetValue(i) & vtkDataSetAttributes::HIDDENPOINT)
                    out->n_hidden++;
        vtkDataArray *a = grid->GetPointData()->GetArray(field_name);
        if (a) {
            out->field = (float *)std::malloc(sizeof(float) * (size_t)out->n_points);
            for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
                out->field[i] = (float)a->GetTuple1(i);
        }
        return 0;
    } catch (...) {
        std::snprintf(out->error, sizeof out->error, "C++ exception reading '%s'", path);
        return -1;
    }
}

void vts_data_free(vts_data *d)
{
    std::free(d->xyz);
    std::free(d->field);
    d->xyz = nullptr;
    d->field = nullptr;
}
