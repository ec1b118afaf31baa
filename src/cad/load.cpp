// Reading STEP, IGES and BREP files into a CadModel.
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Shape.hxx>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>

#include "impl.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cad {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  std::string line = "cannot load CAD file '" + path + "': " + reason;
  std::replace(line.begin(), line.end(), '\n', ' ');
  throw InputError(line);
}

enum class Format { Step, Iges, Brep };

TopoDS_Shape read_shape(const std::string& path, Format format) {
  TopoDS_Shape shape;
  if (format == Format::Brep) {
    BRep_Builder builder;
    if (!BRepTools::Read(shape, path.c_str(), builder)) fail(path, "not a readable BREP file");
    return shape;
  }
  if (format == Format::Step) {
    STEPControl_Reader reader;
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) fail(path, "not a readable STEP file");
    if (reader.TransferRoots() <= 0) fail(path, "STEP file has no transferable shape");
    return reader.OneShape();
  }
  IGESControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) fail(path, "not a readable IGES file");
  if (reader.TransferRoots() <= 0) fail(path, "IGES file has no transferable shape");
  return reader.OneShape();
}

}  // namespace

CadModel load_cad(const std::string& path, const LoadOptions& options) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  Format format;
  if (ext == ".step" || ext == ".stp") {
    format = Format::Step;
  } else if (ext == ".iges" || ext == ".igs") {
    format = Format::Iges;
  } else if (ext == ".brep" || ext == ".brp") {
    format = Format::Brep;
  } else {
    fail(path,
         "unsupported extension '" + ext + "' (expected .step, .stp, .iges, .igs, .brep or .brp)");
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "file does not exist");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (fs::file_size(path, ec) == 0 || ec) fail(path, "file is empty");

  TopoDS_Shape shape;
  try {
    shape = read_shape(path, format);
  } catch (const Standard_Failure& e) {
    fail(path, std::string("reader failed: ") + e.GetMessageString());
  }
  if (shape.IsNull()) fail(path, "no shape in file");
  if (!TopExp_Explorer(shape, TopAbs_FACE).More()) fail(path, "shape has no face");

  if (options.sew) {
    try {
      double tol = options.sew_tolerance;
      if (tol <= 0) {
        Bnd_Box box;
        BRepBndLib::Add(shape, box, false);
        double x0, y0, z0, x1, y1, z1;
        box.Get(x0, y0, z0, x1, y1, z1);
        tol =
            1e-6 * std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) + (z1 - z0) * (z1 - z0));
      }
      BRepBuilderAPI_Sewing sewing(tol);
      sewing.Add(shape);
      sewing.Perform();
      const TopoDS_Shape sewn = sewing.SewedShape();
      if (!sewn.IsNull() && TopExp_Explorer(sewn, TopAbs_FACE).More()) shape = sewn;
    } catch (const Standard_Failure& e) {
      fail(path, std::string("sewing failed: ") + e.GetMessageString());
    }
  }
  return ModelBuilder::build(shape, path, options.measure_faces);
}

}  // namespace qsmesh::cad

namespace qsmesh::cad {

void set_kernel_messages(bool quiet) {
  const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
  messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  // Quiet: the program reports load failures itself, in one line; the kernel's own parser messages
  // would only repeat them. Verbose: the kernel's warnings go to stderr, never to stdout.
  if (quiet) return;
  Handle(Message_PrinterOStream) printer =
      new Message_PrinterOStream("cerr", Standard_False, Message_Warning);
  printer->SetToColorize(Standard_False);
  messenger->AddPrinter(printer);
}

}  // namespace qsmesh::cad
